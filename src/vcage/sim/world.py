"""The simulated world: model and data, stepping at a control rate, state save/restore.

Instability (NaN or exploding velocities) raises :class:`SimulationError` at the control step where
it appears, so an unstable rollout is never recorded.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import mujoco
import numpy as np

from vcage.config import SimConfig
from vcage.errors import SimulationError
from vcage.geometry import mat_to_quat
from vcage.sim.robot import PREFIX as ROBOT_PREFIX
from vcage.sim.robot import Robot

STATE_SPEC = mujoco.mjtState.mjSTATE_INTEGRATION
_BAD_STATE = (int(mujoco.mjtWarning.mjWARN_BADQPOS), int(mujoco.mjtWarning.mjWARN_BADQVEL),
              int(mujoco.mjtWarning.mjWARN_BADQACC))


@dataclass(frozen=True)
class ObjectInstance:
    """A catalog object placed in the world: instance name, catalog type and its root body id."""

    name: str
    type_name: str
    body_id: int
    scale: float
    color: str


class World:
    """A compiled scene with a robot; the only place ``mj_step`` is called during execution."""

    def __init__(self, model: mujoco.MjModel, objects: dict[str, ObjectInstance],
                 sim: SimConfig = SimConfig(), spec: Callable[[], mujoco.MjSpec] | None = None) -> None:
        self.model = model
        # builds the MjSpec ``model`` was compiled from, if known (renderers recompile it for drawing)
        self.spec = spec
        self.data = mujoco.MjData(model)
        self.sim = sim
        self.objects = objects
        self.robot = Robot(model)
        self.substeps = sim.substeps
        self.physics_seconds = 0.0  # wall time spent in step(), to relate a run's total to physics
        self._scratch: mujoco.MjData | None = None  # kinematics off the simulation (object_poses, tcp_poses)
        self._root_to_object = np.full(model.nbody, -1, dtype=np.int32)
        self.object_names = list(objects)
        for idx, inst in enumerate(objects.values()):
            self._root_to_object[inst.body_id] = idx
        self.robot_bodies = np.array([model.body(i).name.startswith(ROBOT_PREFIX)
                                      for i in range(model.nbody)])
        self.reset()

    @property
    def control_dt(self) -> float:
        return self.substeps * self.model.opt.timestep

    def reset(self) -> None:
        """Back to the model's ``home`` keyframe (robot at home, objects where composed)."""
        key = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_KEY, "home")
        if key >= 0:
            mujoco.mj_resetDataKeyframe(self.model, self.data, key)
        else:
            mujoco.mj_resetData(self.model, self.data)
        self.forward()

    def forward(self) -> None:
        """Recompute derived quantities (contacts, positions) without advancing time."""
        try:
            mujoco.mj_forward(self.model, self.data)
        except mujoco.FatalError as exc:
            raise SimulationError(_fatal_message(exc)) from exc

    def step(self, ctrl: np.ndarray | None = None) -> None:
        """Apply ``ctrl`` (if given) and advance one control period; raise if unstable."""
        if ctrl is not None:
            self.data.ctrl[:] = ctrl
        t0, sim_time = time.perf_counter(), self.data.time
        before = self._bad_state_warnings()
        try:
            mujoco.mj_step(self.model, self.data, nstep=self.substeps)
        except mujoco.FatalError as exc:
            raise SimulationError(_fatal_message(exc)) from exc
        finally:
            self.physics_seconds += time.perf_counter() - t0
        if self._bad_state_warnings() > before:  # MuJoCo reset the data after NaN/Inf/huge values
            raise SimulationError(
                f"simulation unstable near t={sim_time:.3f}s: MuJoCo found NaN, Inf or huge "
                "values in the state and reset it; reduce the timestep or check the scene for "
                "interpenetrating objects"
            )
        self.check_stable()

    def _bad_state_warnings(self) -> int:
        w = self.data.warning
        return sum(int(w[i].number) for i in _BAD_STATE)

    def settle(self, seconds: float) -> None:
        """Advance with the current controls for ``seconds`` (e.g. to let objects come to rest)."""
        for _ in range(max(1, round(seconds / self.control_dt))):
            self.step()

    def check_stable(self) -> None:
        d = self.data
        speed = np.max(np.abs(d.qvel)) if d.qvel.size else 0.0
        if not (np.isfinite(speed) and np.all(np.isfinite(d.qpos))) or speed > self.sim.max_qvel:
            dof = int(np.nanargmax(np.where(np.isfinite(d.qvel), np.abs(d.qvel), np.inf)))
            joint = self.model.joint(int(self.model.dof_jntid[dof])).name or f"dof {dof}"
            raise SimulationError(
                f"simulation unstable at t={d.time:.3f}s: joint {joint!r} velocity "
                f"{d.qvel[dof]:.3g} (limit {self.sim.max_qvel}); reduce the timestep or check "
                "the scene for interpenetrating objects"
            )

    # -- state -------------------------------------------------------------------------------
    def get_state(self) -> np.ndarray:
        """The full integration state (time, qpos, qvel, act, ctrl, ...) for exact replay."""
        state = np.empty(mujoco.mj_stateSize(self.model, STATE_SPEC))
        mujoco.mj_getState(self.model, self.data, state, STATE_SPEC)
        return state

    def set_state(self, state: np.ndarray) -> None:
        mujoco.mj_setState(self.model, self.data, np.asarray(state, dtype=float), STATE_SPEC)
        self.forward()

    def show_state(self, state: np.ndarray) -> None:
        """Set ``state`` and compute only what drawing it needs: the poses of bodies, geoms, sites,
        cameras and lights, and tendon paths; not contacts, forces or sensors (use
        :meth:`set_state` before reading those; a step recomputes everything)."""
        mujoco.mj_setState(self.model, self.data, np.asarray(state, dtype=float), STATE_SPEC)
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_comPos(self.model, self.data)
        mujoco.mj_camlight(self.model, self.data)
        if self.model.ntendon:
            mujoco.mj_tendon(self.model, self.data)

    # -- object queries ----------------------------------------------------------------------
    def object(self, name: str) -> ObjectInstance:
        try:
            return self.objects[name]
        except KeyError:
            from vcage.errors import SceneError

            raise SceneError(f"no object {name!r} in the scene; objects: {sorted(self.objects)}") from None

    def object_poses(self, names: list[str] | tuple[str, ...], state: np.ndarray | None = None) -> np.ndarray:
        """(len(names), 7) poses of the objects' root bodies: position and quaternion (w, x, y, z)
        with ``w >= 0``, from the kinematics of ``state`` (default: the current ``qpos``).

        Computed in a scratch copy of the data, so the simulation is not touched: after
        :meth:`step` the world's own body poses lag its ``qpos`` by the step (MuJoCo computes them
        before integrating); these never do.
        """
        ids = [self.object(n).body_id for n in names]
        scratch = self._scratch_data()
        if state is None:
            scratch.qpos[:] = self.data.qpos
        else:
            mujoco.mj_setState(self.model, scratch, np.asarray(state, dtype=float), STATE_SPEC)
        mujoco.mj_kinematics(self.model, scratch)
        quat = scratch.xquat[ids].copy()
        quat[quat[:, 0] < 0] *= -1.0
        return np.column_stack([scratch.xpos[ids], quat])

    def _scratch_data(self) -> mujoco.MjData:
        """The data in which kinematics are computed off the simulation (made on first use)."""
        if self._scratch is None:
            self._scratch = mujoco.MjData(self.model)
        return self._scratch

    def tcp_poses(self, arm_qs: np.ndarray) -> np.ndarray:
        """(T, 7) tool-centre-point poses (position, quaternion ``w >= 0``) the arm would have at each
        row of ``arm_qs`` (T, 7), from forward kinematics in the scratch data (the simulation is not
        touched): e.g. where a sequence of joint targets puts the hand."""
        scratch, robot = self._scratch_data(), self.robot
        scratch.qpos[:] = self.data.qpos
        out = np.empty((len(arm_qs), 7))
        for i, q in enumerate(np.asarray(arm_qs, dtype=float)):
            scratch.qpos[robot.arm_qpos] = q
            mujoco.mj_kinematics(self.model, scratch)
            pos, mat = robot.tcp_pose(scratch)
            out[i] = np.concatenate([pos, mat_to_quat(mat)])
        return out

    def object_pos(self, name: str) -> np.ndarray:
        return self.data.xpos[self.object(name).body_id].copy()

    def object_mat(self, name: str) -> np.ndarray:
        return self.data.xmat[self.object(name).body_id].reshape(3, 3).copy()

    def object_com(self, name: str) -> np.ndarray:
        """Centre of mass of ``name``'s bodies (its root and everything attached to it)."""
        return self.data.subtree_com[self.object(name).body_id].copy()

    def object_lowest(self, name: str, up: np.ndarray, origin: np.ndarray) -> float:
        """Height along the unit vector ``up``, from ``origin``, of the lowest point of ``name``'s
        collision geoms: each box, sphere, capsule or cylinder's support point against ``-up``."""
        geoms = self._collision_geoms(name)
        m, d = self.model, self.data
        up = np.asarray(up, dtype=float)
        low = np.inf
        for g in geoms:
            c, rot, size = d.geom_xpos[g] - origin, d.geom_xmat[g].reshape(3, 3), m.geom_size[g]
            n = rot.T @ up  # ``up`` in the geom's frame
            gtype = int(m.geom_type[g])
            if gtype == mujoco.mjtGeom.mjGEOM_BOX:
                depth = -float(np.abs(n) @ size)
            elif gtype == mujoco.mjtGeom.mjGEOM_SPHERE:
                depth = -float(size[0])
            elif gtype == mujoco.mjtGeom.mjGEOM_CAPSULE:
                depth = -float(abs(n[2]) * size[1] + size[0])
            elif gtype == mujoco.mjtGeom.mjGEOM_CYLINDER:
                depth = -float(abs(n[2]) * size[1] + size[0] * np.sqrt(max(0.0, 1.0 - n[2] ** 2)))
            else:  # no catalog object has other shapes: their bounding sphere, which reaches lower
                depth = -float(m.geom_rbound[g])
            low = min(low, float(c @ up) + depth)
        return low

    def _collision_geoms(self, name: str) -> np.ndarray:
        """Ids of ``name``'s geoms that take part in contacts (not its decorations)."""
        idx = self.object_names.index(name)
        ids = np.arange(self.model.ngeom)
        solid = (self.model.geom_contype != 0) | (self.model.geom_conaffinity != 0)
        return ids[(self.object_of_geom(ids) == idx) & solid]

    def object_of_geom(self, geom_ids: np.ndarray) -> np.ndarray:
        """Index into :attr:`object_names` of each geom's object, or -1 for non-objects."""
        roots = self.model.body_rootid[self.model.geom_bodyid[geom_ids]]
        return self._root_to_object[roots]

    def geom_is_robot(self, geom_ids: np.ndarray) -> np.ndarray:
        return self.robot_bodies[self.model.geom_bodyid[geom_ids]]

    def body_owner(self, body_id: int) -> str:
        """The object a body belongs to, else the name of its root body (``table``, the robot's
        base, ``world`` for the floor)."""
        root = int(self.model.body_rootid[body_id])
        idx = int(self._root_to_object[root])
        if idx >= 0:
            return self.object_names[idx]
        return self.model.body(root).name or "world"

    def table_top(self) -> float:
        """Height of the table's top surface."""
        geom = self.model.geom("table/top")
        return float(self.data.geom_xpos[geom.id][2] + geom.size[2])

    def joint_value(self, name: str) -> float:
        return float(self.data.joint(name).qpos[0])


def _fatal_message(exc: Exception) -> str:
    first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
    return (f"MuJoCo gave up on this state ({first}); usually objects interpenetrate deeply and "
            "generate more contacts than the solver's memory holds: check the scene's placement")
