"""The critic interface: a verdict on one subtask from what the critic is allowed to see.

An :class:`Observation` holds rendered views (RGB and segmentation, before and after the subtask)
and the subtask's description and predicates; ``oracle`` carries the ground-truth predicate values,
which only the oracle critic reads.
"""

from __future__ import annotations

import copy
import json
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from vcage.backends import BackendConfig
from vcage.config import from_fields
from vcage.errors import ConfigError
from vcage.planning.schema import Subtask
from vcage.registry import Registry


@dataclass(frozen=True)
class View:
    rgb: np.ndarray  # (H, W, 3) uint8
    segmentation: np.ndarray  # (H, W) int32: object index into Observation.labels, -1 other, -2 robot
    depth: np.ndarray | None = None  # (H, W) metres along the view axis (orthographic: straight down)
    pixel_size: float | None = None  # metres per pixel on the table (orthographic cameras)
    robot_base: tuple[float, float] | None = None  # (row, col) of the robot's base (orthographic cameras)


@dataclass(frozen=True)
class Observation:
    subtask: Subtask
    labels: tuple[str, ...]  # object names by segmentation index
    before: dict[str, View] = field(default_factory=dict)  # camera -> view before the subtask
    after: dict[str, View] = field(default_factory=dict)  # camera -> view after it
    during: dict[str, View] = field(default_factory=dict)  # at the subtask's deepest moment (a press)
    types: dict[str, str] = field(default_factory=dict)  # object name -> catalog type (from the plan)
    oracle: dict[str, bool] = field(default_factory=dict)  # ground truth (the oracle critic only)


class Reason(str):
    """Why a check failed: its text (a ``str``, compared and printed as the text) and ``code``, a short
    snake_case name of the cause, so that rejections can be counted by cause without reading the
    text (``Reason("too_shallow", "the hand stopped 3.1 mm short of pressing bell")``)."""

    code: str

    def __new__(cls, code: str, text: str) -> Reason:
        self = super().__new__(cls, text)
        self.code = code
        return self

    def __getnewargs__(self) -> tuple[str, str]:  # type: ignore[override]  # pickles and copies keep the code
        return self.code, str(self)


@dataclass(frozen=True)
class Verdict:
    """``codes``: machine-readable causes of a rejection (e.g. ``pressed.too_shallow``), none when the
    critic accepts or gives no codes."""

    accept: bool
    reason: str
    details: dict[str, Any] = field(default_factory=dict)
    codes: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"accept": self.accept, "reason": self.reason}
        if self.details:
            out["details"] = self.details
        if self.codes:
            out["codes"] = list(self.codes)
        return out


class Critic(ABC):
    name: str = ""
    needs_views: bool = True  # whether the pipeline must render views for it

    @abstractmethod
    def judge(self, obs: Observation) -> Verdict:
        """Accept or reject the subtask's outcome.

        Model-based critics raise :class:`~vcage.errors.BackendUnavailableError` when their model
        cannot answer: an outage is never a verdict.
        """

    def preflight(self) -> None:
        """Check, before any episode is simulated, that the critic can judge (e.g. its model endpoint
        answers); raises :class:`~vcage.errors.BackendUnavailableError` if not. The default has
        nothing to check."""

    def version(self) -> str:
        """What judged: the critic and the version of its rules, recorded with every verdict, so that
        episodes judged under different rules can be told apart (the default: the critic's name)."""
        return self.name

    def rules(self) -> dict[str, Any]:
        """The numbers the critic's rules compare with (recorded once per generation run); none by
        default."""
        return {}


class Recorder(Critic):
    """Accepts every subtask and keeps what it was shown, in order (``seen``): the rollout goes on
    whatever happened, so a benchmark or a test can judge each observation afterwards, with any
    critic, beside the oracle's label of the same subtask. Not registered: it judges nothing.
    ``needs_views``: render the views a critic that needs them would be shown (the default)."""

    def __init__(self, needs_views: bool = True) -> None:
        self.seen: list[Observation] = []
        self.needs_views = needs_views

    def judge(self, obs: Observation) -> Verdict:
        self.seen.append(obs)
        return Verdict(True, "recorded; the rollout goes on")


@dataclass(frozen=True)
class CriticConfig:
    """Which critic judges each subtask, and its options.

    ``backend`` is the model endpoint of a model-based critic (``vlm``); when it is None the
    ``VCAGE_VLM_*`` environment variables are read once, when the run's configuration is resolved,
    and the result is stored with the dataset like any other option. ``votes``, ``rule`` and
    ``malformed_verdict`` apply to the ``vlm`` critic: how many times it is asked, how the answers
    combine (``majority`` or ``all``), and what an unusable answer counts as. ``thresholds`` apply to
    the ``image`` critic: its thresholds by name (:mod:`vcage.critics.image.thresholds`) in place of
    their defaults, kept as JSON values; stored only when some are given.
    """

    name: str = "image"
    backend: BackendConfig | None = None
    votes: int = 1
    rule: str = "majority"
    malformed_verdict: bool = False
    thresholds: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        CRITICS.get(self.name)  # an unknown name lists the valid ones
        if not isinstance(self.thresholds, Mapping):
            raise ConfigError(f"critic thresholds must map names to values, got {self.thresholds!r}")
        if self.thresholds:
            if self.name not in THRESHOLDS:
                raise ConfigError(f"critic thresholds apply to the {', '.join(THRESHOLDS.names())} critic, "
                                  f"not to {self.name!r}")
            given = THRESHOLDS.get(self.name)(self.thresholds)  # refuses an unknown name or a wrong kind
            object.__setattr__(self, "thresholds", {name: given[name] for name in self.thresholds})
        if isinstance(self.votes, bool) or not isinstance(self.votes, int) or self.votes < 1:
            raise ConfigError(f"critic votes must be an integer >= 1, got {self.votes!r}")
        if self.rule not in ("majority", "all"):
            raise ConfigError(f"critic rule {self.rule!r}; valid: majority, all")

    def to_dict(self) -> dict[str, Any]:
        data = {"name": self.name, "backend": self.backend.to_dict() if self.backend else None,
                "votes": self.votes, "rule": self.rule, "malformed_verdict": self.malformed_verdict}
        if self.thresholds:  # a configuration with the defaults is stored as before the field existed
            data["thresholds"] = copy.deepcopy(self.thresholds)
        return data

    def __hash__(self) -> int:  # hashable as before ``thresholds`` (a dict) existed
        return hash(json.dumps(self.to_dict(), sort_keys=True))

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> CriticConfig:
        return from_fields(cls, data, backend=BackendConfig)


CriticFactory = Callable[[CriticConfig], Critic]
CRITICS: Registry[CriticFactory] = Registry("critic")
# The critics that take thresholds: each checks the overrides given by name and returns their values,
# as they are stored (a ConfigError for an unknown name or a value not of its kind).
ThresholdCheck = Callable[[Mapping[str, Any]], dict[str, Any]]
THRESHOLDS: Registry[ThresholdCheck] = Registry("critic with thresholds")


def make_critic(config: CriticConfig) -> Critic:
    """The critic ``config`` names, built from it."""
    return CRITICS.get(config.name)(config)
