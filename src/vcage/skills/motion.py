"""Motion plans: joint-space waypoints with timing, as returned by every skill."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Waypoint:
    """Reach arm joints ``q`` with the gripper command ``gripper`` (1 open, 0 closed) in ``duration`` s.

    ``hold`` keeps the final command for that many extra seconds (e.g. to let the gripper close).
    """

    q: np.ndarray
    gripper: float
    duration: float
    hold: float = 0.0
    label: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "q", np.asarray(self.q, dtype=float).copy())
        if self.duration < 0 or self.hold < 0:
            raise ValueError("waypoint duration and hold must be non-negative")


@dataclass(frozen=True)
class MotionPlan:
    """An ordered list of waypoints produced by a skill, named for logs and datasets."""

    skill: str
    waypoints: tuple[Waypoint, ...] = field(default_factory=tuple)

    def __add__(self, other: MotionPlan) -> MotionPlan:
        name = self.skill if not other.skill or other.skill == self.skill else f"{self.skill}+{other.skill}"
        return MotionPlan(name, self.waypoints + other.waypoints)

    @property
    def duration(self) -> float:
        return sum(w.duration + w.hold for w in self.waypoints)

    @property
    def final_q(self) -> np.ndarray:
        return self.waypoints[-1].q

    @property
    def final_gripper(self) -> float:
        return self.waypoints[-1].gripper


def min_jerk(s: np.ndarray) -> np.ndarray:
    """Minimum-jerk time scaling of ``s`` in [0, 1]."""
    return 10 * s**3 - 15 * s**4 + 6 * s**5
