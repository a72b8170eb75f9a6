"""The funnel of a dataset's attempts: how many ended at each stage, and why they were rejected.

Counted from the attempt log (every attempt of every run that committed an episode), so the
numbers are the dataset's, whatever runs made it. Rejection reasons are grouped as ``vcage
generate`` groups them when it prints a run's funnel: by the first of the critic's reason codes
where the record has them (``pressed.too_shallow``), else by the reason's first clause, numbers
replaced by ``N`` (a skill's failure, a critic without codes, a log written before codes were).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from vcage.pipeline.attempt_log import rejection_group
from vcage.pipeline.stage import Stage

STAGES = tuple(Stage)  # the order stages are shown in: where an attempt can end, then accepted


@dataclass(frozen=True)
class ReasonCount:
    stage: str
    reason: str
    attempts: int


@dataclass(frozen=True)
class FunnelCounts:
    attempts: int
    accepted: int
    samples: int  # episodes attempted (sample indices)
    given_up: int  # samples whose every attempt was rejected
    stages: dict[str, int]  # every stage, in STAGES order, zeros included
    reasons: tuple[ReasonCount, ...]  # most attempts first

    @property
    def rejected(self) -> int:
        return self.attempts - self.accepted

    @property
    def acceptance(self) -> float:
        """Accepted attempts per attempt."""
        return self.accepted / self.attempts if self.attempts else 0.0


def count(records: Sequence[dict[str, Any]]) -> FunnelCounts:
    """The funnel of attempt-log ``records`` (see :mod:`vcage.pipeline.attempt_log`)."""
    stages: Counter[str] = Counter()
    reasons: Counter[tuple[str, str]] = Counter()
    accepted_samples: set[int] = set()
    samples: set[int] = set()
    for rec in records:
        stage = str(rec["stage"])
        stages[stage] += 1
        samples.add(int(rec["episode"]))
        if stage == Stage.ACCEPTED:
            accepted_samples.add(int(rec["episode"]))
        else:
            reasons[(stage, rejection_group(rec))] += 1
    known = {str(s): stages.get(str(s), 0) for s in STAGES}
    known.update({s: n for s, n in stages.items() if s not in known})  # a stage of a newer version
    return FunnelCounts(
        attempts=sum(stages.values()), accepted=stages.get(Stage.ACCEPTED, 0), samples=len(samples),
        given_up=len(samples - accepted_samples), stages=known,
        reasons=tuple(ReasonCount(s, r, n) for (s, r), n in reasons.most_common()))
