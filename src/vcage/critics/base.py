"""The critic interface: a verdict on one subtask from what the critic is allowed to see.

An :class:`Observation` holds rendered views (RGB and segmentation, before and after the subtask)
and the subtask's description and predicates; ``oracle`` carries the ground-truth predicate values,
which only the oracle critic reads.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from vcage.planning.schema import Subtask
from vcage.registry import Registry


@dataclass(frozen=True)
class View:
    rgb: np.ndarray  # (H, W, 3) uint8
    segmentation: np.ndarray  # (H, W) int32: object index into Observation.labels, -1 other, -2 robot
    depth: np.ndarray | None = None  # (H, W) metres along the view axis (perspective cameras)


@dataclass(frozen=True)
class Observation:
    subtask: Subtask
    labels: tuple[str, ...]  # object names by segmentation index
    before: dict[str, View] = field(default_factory=dict)  # camera -> view before the subtask
    after: dict[str, View] = field(default_factory=dict)  # camera -> view after it
    during: dict[str, View] = field(default_factory=dict)  # at the subtask's deepest moment (a press)
    oracle: dict[str, bool] = field(default_factory=dict)  # ground truth (the oracle critic only)


@dataclass(frozen=True)
class Verdict:
    accept: bool
    reason: str
    details: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"accept": self.accept, "reason": self.reason}
        if self.details:
            out["details"] = self.details
        return out


class Critic(ABC):
    name: str = ""
    needs_views: bool = True  # whether the pipeline must render views for it

    @abstractmethod
    def judge(self, obs: Observation) -> Verdict:
        """Accept or reject the subtask's outcome."""


CriticFactory = Callable[..., Critic]
CRITICS: Registry[CriticFactory] = Registry("critic")
