"""Recovery data from the expert (DART-style): executed commands pushed off the plan, clean labels kept.

Every demonstration of the scripted expert starts at the same home posture and follows its plan
without error, so a policy trained on them has never seen a state off the demonstrated path, nor
the command that leads back to it. Here a seeded :class:`Perturbation` pushes the *executed* arm
command of a share of the motion segments (the waypoints of a motion plan) off the plan by a
smooth bump: zero at the segment's start and end, ``sin(pi s)`` times a random joint offset in
between. The recording keeps the plan's own command as the action: position targets on the
demonstrated path, which from the pushed state are the way back to it (the label DART asks of the
expert). Holds (gripper closing, settling) and the gripper command are never pushed. The arm's
start can be moved off home too (``start_noise``), so episodes do not all begin in one posture.

A pushed segment can make the subtask fail (a grasp missed because the hand arrived late, a
neighbour brushed): the critic judges such an episode like any other and it is re-sampled, so the
recovery data in a verified dataset is recovery that worked. The perturbation's random stream is
its own (from the attempt's seed), so turning it on changes no other draw of the attempt; a config
without it (``GenerateConfig.recovery = None``) makes the same episodes as before it existed.

The stored actions are the clean commands, not the executed ones: replaying an episode's actions
from its first state does not reproduce its frames when recovery is on (its states do).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from vcage.config import from_fields
from vcage.errors import ConfigError
from vcage.sim.world import World

RECOVERY_STREAM = 0x5EC0  # mixed with the attempt's seed: the perturbation's own random stream
MAX_NOISE = 0.3  # rad: beyond this a pushed arm is no longer near its plan


@dataclass(frozen=True)
class RecoveryConfig:
    """How often and how far the executed commands leave the plan; off by default (``fraction`` 0).

    ``fraction``: the share of motion segments whose executed command is pushed; ``joint_noise``:
    standard deviation (rad) of each arm joint's peak offset on a pushed segment; ``start_noise``:
    standard deviation (rad) of each arm joint's offset from home at the episode's start.
    """

    fraction: float = 0.0
    joint_noise: float = 0.05
    start_noise: float = 0.0

    def __post_init__(self) -> None:
        for name in ("fraction", "joint_noise", "start_noise"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
                raise ConfigError(f"recovery.{name} must be a number, got {value!r}")
            object.__setattr__(self, name, float(value))
        if not 0.0 <= self.fraction <= 1.0:
            raise ConfigError(f"recovery.fraction is a share of motion segments, in [0, 1]: got "
                              f"{self.fraction}")
        for name in ("joint_noise", "start_noise"):
            value = getattr(self, name)
            if not 0.0 <= value <= MAX_NOISE:
                raise ConfigError(f"recovery.{name} must be in [0, {MAX_NOISE}] rad, got {value}")

    @property
    def active(self) -> bool:
        return (self.fraction > 0 and self.joint_noise > 0) or self.start_noise > 0

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: Any) -> RecoveryConfig:
        return from_fields(cls, data)


class Perturbation:
    """The seeded pushes of one attempt: :meth:`offsets` for each motion segment, in order."""

    def __init__(self, config: RecoveryConfig, seed: int) -> None:
        self.config = config
        self.rng = np.random.default_rng([int(seed), RECOVERY_STREAM])
        self.pushed = 0  # segments pushed so far
        self.segments = 0  # segments seen so far

    def start_offset(self, joints: int) -> np.ndarray:
        """The arm's offset from home at the episode's start (zeros when ``start_noise`` is 0)."""
        if self.config.start_noise <= 0:
            return np.zeros(joints)
        return self.rng.normal(0.0, self.config.start_noise, joints)

    def offsets(self, ticks: int, joints: int) -> np.ndarray | None:
        """Offsets (ticks, joints) to add to the executed command over a segment of ``ticks`` control
        steps, or None when this segment is not pushed. Every segment draws the same numbers whether
        pushed or not, so one segment's fate does not shift the next one's."""
        self.segments += 1
        push = self.rng.random() < self.config.fraction
        peak = self.rng.normal(0.0, self.config.joint_noise, joints)
        if not push or ticks < 3 or self.config.joint_noise <= 0:
            return None
        self.pushed += 1
        s = np.arange(1, ticks + 1) / ticks
        return np.sin(np.pi * s)[:, None] * peak[None, :]


def move_start(world: World, perturbation: Perturbation) -> None:
    """Move the arm off its posture by the perturbation's start offset (within the joint limits);
    the objects stay as they settled, and the actuators are set to hold the new posture."""
    robot, data = world.robot, world.data
    low, high = robot.arm_limits[:, 0], robot.arm_limits[:, 1]
    q = np.clip(robot.arm_q(data) + perturbation.start_offset(len(robot.arm_qpos)), low, high)
    data.qpos[robot.arm_qpos] = q
    data.ctrl[:] = robot.ctrl(q, 1.0 if robot.gripper_width(data) > 0.04 else 0.0)
    world.forward()
