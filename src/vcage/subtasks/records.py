"""The rows of the subtask database as frozen values: a scene, a verified subtask, one trial."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

ACCEPTED, REJECTED = "accepted", "rejected"
TEMPLATE, LLM = "template", "llm"
SUCCESS, FAILURE = "success", "failure"


@dataclass(frozen=True)
class SceneRecord:
    """A scene subtasks were verified in: its id (hash of the spec), where it came from, the spec."""

    id: str
    source: str  # "task:<name>@<seed>" or the path of a scene_spec.json
    spec: dict[str, Any]


@dataclass(frozen=True)
class TrialRecord:
    """One simulated trial: its seed, outcome, failure class (None on success), and wall time."""

    trial: int
    seed: int
    outcome: str  # SUCCESS | FAILURE
    failure_class: str | None = None
    detail: str = ""
    seconds: float = 0.0

    @property
    def success(self) -> bool:
        return self.outcome == SUCCESS


@dataclass(frozen=True)
class SubtaskRecord:
    """A candidate subtask after verification: what it does, its code, where the code came from,
    its trials' success rate with the Wilson interval, and whether it was accepted (SR > 0.5)."""

    id: str
    scene_id: str
    skill: str
    parameters: dict[str, Any]
    description: str
    predicates: tuple[str, ...]
    code: str
    code_hash: str
    source: str  # TEMPLATE | LLM
    trials: int
    successes: int
    success_rate: float
    ci_low: float
    ci_high: float
    status: str  # ACCEPTED | REJECTED
    reason: str
    model: str | None = None
    prompt_hash: str | None = None
    critic: str | None = None
    versions: dict[str, str] = field(default_factory=dict)
    created: str = ""

    def to_dict(self) -> dict[str, Any]:
        out = asdict(self)
        out["predicates"] = list(self.predicates)
        return out
