"""The rejected attempts of a dataset, each with where it ended, why, and what the oracle says.

A rejection *disagrees* when the critic and the oracle differ on a subtask the critic judged: a
false reject (the critic rejected a subtask the oracle says succeeded) or, earlier in the same
attempt, a false accept. Disagreements are listed first: they are the rejections worth a look.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from vcage.pipeline.stage import Stage


@dataclass(frozen=True)
class Rejection:
    sample: int  # the attempt log's ``episode``: the sample index whose seeds the attempt used
    attempt: int
    seed: int
    stage: str
    reason: str
    subtask: int | None = None  # index of the subtask the attempt ended at, if it ran one
    description: str = ""
    critic_accept: bool | None = None  # the critic's verdict on that subtask (None: not judged)
    critic_reason: str = ""
    oracle_success: bool | None = None  # the oracle's audit of that subtask
    oracle: dict[str, bool] = field(default_factory=dict)  # predicate -> value
    disagreements: int = 0  # judged subtasks of the attempt where critic and oracle differ
    view: str | None = None  # data URI of the views the critic judged, when stored and shown
    view_note: str = ""  # why there is no view, when there is none

    @property
    def disagrees(self) -> bool:
        return self.disagreements > 0


def disagreements(record: dict[str, Any]) -> int:
    """Judged subtasks of an attempt-log record where the critic's verdict is not the oracle's."""
    return sum(bool(verdict.get("accept")) != bool(audit["oracle_success"])
               for audit, verdict in zip(record["audit"], record["verdicts"], strict=False) if verdict)


def rejection(record: dict[str, Any]) -> Rejection:
    audit = record["audit"][-1] if record["audit"] else None
    verdict = record["verdicts"][-1] if record["verdicts"] else None  # one per audited subtask (or None)
    return Rejection(
        sample=int(record["episode"]), attempt=int(record["attempt"]), seed=int(record["seed"]),
        stage=str(record["stage"]), reason=str(record["reason"]),
        subtask=int(audit["subtask"]) if audit else None, description=audit["description"] if audit else "",
        critic_accept=bool(verdict["accept"]) if verdict else None,
        critic_reason=str(verdict.get("reason", "")) if verdict else "",
        oracle_success=bool(audit["oracle_success"]) if audit else None,
        oracle={str(k): bool(v) for k, v in audit["oracle"].items()} if audit else {},
        disagreements=disagreements(record))


def rejections(records: Sequence[dict[str, Any]]) -> list[Rejection]:
    """Every rejected attempt of ``records``: disagreements first, then in log order."""
    found = [rejection(r) for r in records if r["stage"] != Stage.ACCEPTED]
    return sorted(found, key=lambda r: not r.disagrees)  # stable: log order within each group
