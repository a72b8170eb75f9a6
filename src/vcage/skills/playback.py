"""Plays motion plans back on a :class:`World` with position control at the control rate, recording.

Per control step the player records joint positions, gripper width, the TCP pose, and the
commanded action (7 arm joint targets and the gripper command), which is what a dataset stores.
With a :class:`~vcage.skills.recovery.Perturbation` the executed arm command of some segments is
pushed off the plan while the recorded action stays the plan's (recovery data).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from vcage.geometry import mat_to_quat
from vcage.sim.world import World
from vcage.skills.motion import MotionPlan, min_jerk
from vcage.skills.recovery import Perturbation

StepHook = Callable[[World], None]


@dataclass
class Recording:
    """Per-step arrays of one rollout; append-only while executing."""

    qpos: list[np.ndarray] = field(default_factory=list)  # (7,) arm joints
    gripper: list[float] = field(default_factory=list)  # finger opening in metres
    ee_pos: list[np.ndarray] = field(default_factory=list)
    ee_quat: list[np.ndarray] = field(default_factory=list)
    action: list[np.ndarray] = field(default_factory=list)  # (8,) arm targets + gripper command
    time: list[float] = field(default_factory=list)
    states: list[np.ndarray] = field(default_factory=list)  # full simulator states, if recorded
    skills: list[tuple[str, int, int]] = field(default_factory=list)  # (skill, first, end) steps

    def __len__(self) -> int:
        return len(self.time)

    def arrays(self) -> dict[str, np.ndarray]:
        return {
            "qpos": np.asarray(self.qpos), "gripper": np.asarray(self.gripper),
            "ee_pos": np.asarray(self.ee_pos), "ee_quat": np.asarray(self.ee_quat),
            "action": np.asarray(self.action), "time": np.asarray(self.time),
        }


class Player:
    """Interpolates waypoints with minimum-jerk timing and steps the world once per control tick."""

    def __init__(self, world: World, record: bool = True, record_states: bool = False,
                 perturbation: Perturbation | None = None) -> None:
        self.world = world
        self.record = record
        self.record_states = record_states  # also keep every step's full state (for replay/video)
        self.perturbation = perturbation  # pushes the executed command of some segments (recovery data)
        self.recording = Recording()
        self.hooks: list[StepHook] = []
        robot = world.robot
        self.q_cmd = robot.arm_q(world.data)
        self.gripper_cmd = 1.0 if robot.gripper_width(world.data) > 0.04 else 0.0

    def run(self, plan: MotionPlan) -> None:
        first = len(self.recording)
        dt = self.world.control_dt
        for wp in plan.waypoints:
            n = max(1, round(wp.duration / dt))
            start_q, start_g = self.q_cmd.copy(), self.gripper_cmd
            s = min_jerk(np.arange(1, n + 1) / n)
            push = None if self.perturbation is None else self.perturbation.offsets(n, len(start_q))
            for k in range(n):
                self._tick(start_q + s[k] * (wp.q - start_q), start_g + s[k] * (wp.gripper - start_g),
                           None if push is None else push[k])
            for _ in range(round(wp.hold / dt)):
                self._tick(wp.q, wp.gripper)
        self.recording.skills.append((plan.skill, first, len(self.recording)))

    def wait(self, seconds: float) -> None:
        for _ in range(max(1, round(seconds / self.world.control_dt))):
            self._tick(self.q_cmd, self.gripper_cmd)

    def _tick(self, q: np.ndarray, gripper: float, push: np.ndarray | None = None) -> None:
        """One control step towards the command ``q``, ``gripper``, executed as ``q + push``; the
        command itself (never the push) is what the recording keeps and the next segment starts from."""
        world = self.world
        self.q_cmd, self.gripper_cmd = np.asarray(q, dtype=float), float(gripper)
        robot = world.robot
        if self.record:
            rec = self.recording
            data = world.data
            pos, mat = robot.tcp_pose(data)
            rec.qpos.append(robot.arm_q(data))
            rec.gripper.append(robot.gripper_width(data))
            rec.ee_pos.append(pos)
            rec.ee_quat.append(mat_to_quat(mat))
            rec.action.append(np.append(self.q_cmd, self.gripper_cmd))
            rec.time.append(float(data.time))
            if self.record_states:
                rec.states.append(world.get_state())
        world.step(robot.ctrl(self.q_cmd if push is None else self.q_cmd + push, self.gripper_cmd))
        for hook in self.hooks:
            hook(world)
