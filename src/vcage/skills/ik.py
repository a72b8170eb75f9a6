"""Differential inverse kinematics with mink (the only module that imports it).

Targets are poses of the tool-centre point (TCP) in the world frame. The solver runs on a
robot-only model mounted where the scene's robot is, so object joints never enter the problem.
"""

from __future__ import annotations

from functools import cache

import mink
import mujoco
import numpy as np

from vcage.errors import IKError, UnreachableError
from vcage.geometry import rot_x, rot_y, rot_z
from vcage.sim.robot import HOME_QPOS, TCP_SITE, attach_panda

SHOULDER_HEIGHT = 0.333  # joint 2 above the base
MAX_REACH = 0.855  # shoulder-to-TCP distance beyond which no configuration exists


def down_rotation(yaw: float, tilt: float = 0.0) -> np.ndarray:
    """TCP orientation pointing down with its x axis at heading ``yaw``; ``tilt`` leans it."""
    return rot_z(yaw) @ rot_x(np.pi) @ rot_y(tilt)


@cache
def _ik_model(mount: tuple[float, float, float]) -> mujoco.MjModel:
    spec = mujoco.MjSpec()
    attach_panda(spec, mount)
    return spec.compile()


class IKSolver:
    """Solves for arm joint positions that put the TCP at a pose, warm-started from a seed."""

    def __init__(self, mount: tuple[float, float, float], pos_tol: float = 0.002,
                 rot_tol: float = 0.02, max_iters: int = 200) -> None:
        self.mount = np.asarray(mount, dtype=float)
        self.model = _ik_model(tuple(mount))
        self.pos_tol, self.rot_tol, self.max_iters = pos_tol, rot_tol, max_iters
        self.config = mink.Configuration(self.model)
        self.task = mink.FrameTask(TCP_SITE, "site", position_cost=1.0, orientation_cost=0.5,
                                   lm_damping=1e-3)
        self.posture = mink.PostureTask(self.model, cost=1e-3)
        self.limits = [mink.ConfigurationLimit(self.model, min_distance_from_limits=0.02)]
        self._home = np.zeros(self.model.nq)
        self._home[:7] = HOME_QPOS
        self.posture.set_target(self._home)

    def check_reachable(self, pos: np.ndarray) -> None:
        shoulder = self.mount + [0.0, 0.0, SHOULDER_HEIGHT]
        dist = float(np.linalg.norm(np.asarray(pos) - shoulder))
        if dist > MAX_REACH:
            raise UnreachableError(
                f"target {np.round(pos, 3).tolist()} is {dist:.3f} m from the shoulder; the Panda "
                f"reaches {MAX_REACH} m: move the object closer to the robot"
            )

    def _descend(self, pos: np.ndarray, rot: np.ndarray, seed: np.ndarray, iters: int, pos_tol: float,
                 rot_tol: float) -> bool:
        """Up to ``iters`` solver steps from ``seed`` towards the pose (within the joint limits);
        whether the errors fell below the tolerances. The configuration reached is ``self.config``."""
        q = np.zeros(self.model.nq)
        q[:7] = seed
        q[7:] = 0.04
        self.config.update(q)
        target = mink.SE3.from_rotation_and_translation(mink.SO3.from_matrix(np.asarray(rot)),
                                                        np.asarray(pos))
        self.task.set_target(target)
        dt = 0.05
        for _ in range(iters):
            err = self.task.compute_error(self.config)
            if np.linalg.norm(err[:3]) < pos_tol and np.linalg.norm(err[3:]) < rot_tol:
                return True
            vel = mink.solve_ik(self.config, [self.task, self.posture], dt, solver="daqp",
                                damping=1e-3, limits=self.limits)
            self.config.integrate_inplace(vel, dt)
        return False

    def solve(self, pos: np.ndarray, rot: np.ndarray, seed: np.ndarray) -> np.ndarray:
        """Arm joint positions (7,) reaching ``pos``/``rot``; raises :class:`IKError` if none."""
        self.check_reachable(pos)
        if self._descend(pos, rot, seed, self.max_iters, self.pos_tol, self.rot_tol):
            return self.config.q[:7].copy()
        err = self.task.compute_error(self.config)
        raise IKError(
            f"IK did not converge to {np.round(pos, 3).tolist()}: position error "
            f"{np.linalg.norm(err[:3]) * 1000:.1f} mm, orientation error {np.linalg.norm(err[3:]):.3f} "
            "rad; the pose may be at the edge of the workspace or against a joint limit"
        )

    def track(self, pos: np.ndarray, rot: np.ndarray, seed: np.ndarray, max_iters: int = 50) -> np.ndarray:
        """Arm joint positions (7,) as close to ``pos``/``rot`` as ``max_iters`` solver steps get from
        ``seed`` (to a quarter of :meth:`solve`'s tolerances), within the joint limits: a Cartesian
        controller's joint target. Never raises: an unreachable pose gives the nearest configuration
        found."""
        hold = np.zeros(self.model.nq)
        hold[:7] = seed
        self.posture.set_target(hold)
        try:
            self._descend(pos, rot, seed, max_iters, self.pos_tol / 4, self.rot_tol / 4)
        finally:
            self.posture.set_target(self._home)
        return self.config.q[:7].copy()

    def fk(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """TCP position and rotation for arm joints ``q``."""
        full = np.zeros(self.model.nq)
        full[:7] = q
        self.config.update(full)
        pose = self.config.get_transform_frame_to_world(TCP_SITE, "site")
        return pose.translation(), pose.rotation().as_matrix()
