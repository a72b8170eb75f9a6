"""Label noise and critic-oracle agreement, from a dataset's attempt log.

Every attempt (accepted or rejected) is logged with the critic's verdict and the oracle's audit
of each subtask it ran. Label noise is the share of accepted episodes that the oracle says failed;
agreement compares the critic's per-subtask verdicts with the oracle's (accept = positive). Where
accepted episodes started with the plan's objects fused into another object (a scene no check
looked at: Vanilla), their label noise is reported apart from the others'.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from vcage.data.layout import ATTEMPTS_LOG
from vcage.errors import DatasetError
from vcage.pipeline.attempt_log import committed_records
from vcage.pipeline.stage import Stage


@dataclass(frozen=True)
class AuditReport:
    attempts: int
    accepted: int
    accepted_oracle_failed: int
    accepted_fused: int  # accepted episodes that started with the plan's objects fused into another
    accepted_fused_oracle_failed: int
    judged_subtasks: int
    true_accept: int
    false_accept: int  # critic accepted, oracle says failed
    false_reject: int  # critic rejected, oracle says succeeded
    true_reject: int

    @property
    def label_noise(self) -> float:
        return self.accepted_oracle_failed / self.accepted if self.accepted else 0.0

    def noise_where(self, fused: bool) -> float | None:
        """Label noise among the accepted episodes that started fused (or clear); None without any."""
        n, bad = self.accepted_fused, self.accepted_fused_oracle_failed
        if not fused:
            n, bad = self.accepted - n, self.accepted_oracle_failed - bad
        return bad / n if n else None

    @property
    def agreement(self) -> float:
        n = self.judged_subtasks
        return (self.true_accept + self.true_reject) / n if n else 0.0

    @property
    def precision(self) -> float:
        n = self.true_accept + self.false_accept
        return self.true_accept / n if n else 0.0

    @property
    def recall(self) -> float:
        n = self.true_accept + self.false_reject
        return self.true_accept / n if n else 0.0

    def to_dict(self) -> dict[str, Any]:
        return {**asdict(self), "label_noise": self.label_noise, "agreement": self.agreement,
                "precision": self.precision, "recall": self.recall}

    def summary(self) -> str:
        head = (f"{self.accepted} accepted episodes of {self.attempts} attempts; label noise "
                f"{self.label_noise:.1%} ({self.accepted_oracle_failed} accepted episodes fail the oracle)\n")
        if self.accepted_fused:
            clear = self.noise_where(False)
            head += (f"{self.accepted_fused} of them started with the plan's objects fused into another "
                     "object (deeper than the scene check allows): label noise "
                     f"{self.noise_where(True):.1%} there, "
                     + (f"{clear:.1%} on the others\n" if clear is not None else "no other episode\n"))
        if not self.judged_subtasks:
            return head + "no critic verdicts to compare (Vanilla mode, or no subtask was judged)"
        return (head +
                f"critic vs oracle on {self.judged_subtasks} judged subtasks: agreement "
                f"{self.agreement:.1%}, "
                f"precision {self.precision:.1%}, recall {self.recall:.1%} "
                f"(false accepts {self.false_accept}, false rejects {self.false_reject})")


def audit(root: Path) -> AuditReport:
    path = Path(root) / ATTEMPTS_LOG
    if not path.is_file():
        raise DatasetError(f"{path} is missing: the dataset was not made by `vcage generate`, or its "
                           "attempt log was removed")
    counts = dict.fromkeys(("attempts", "accepted", "accepted_oracle_failed", "accepted_fused",
                            "accepted_fused_oracle_failed", "judged_subtasks", "true_accept",
                            "false_accept", "false_reject", "true_reject"), 0)
    for rec in committed_records(Path(root)):  # the episodes a repair dropped are not counted
        counts["attempts"] += 1
        if rec["stage"] == Stage.ACCEPTED:
            fused = bool(rec.get("fused_at_start"))  # absent from logs written before it was recorded
            counts["accepted"] += 1
            counts["accepted_oracle_failed"] += not rec["oracle_success"]
            counts["accepted_fused"] += fused
            counts["accepted_fused_oracle_failed"] += fused and not rec["oracle_success"]
        for audit_row, verdict in zip(rec["audit"], rec["verdicts"], strict=False):
            if not verdict:
                continue
            counts["judged_subtasks"] += 1
            critic, oracle = bool(verdict.get("accept")), bool(audit_row["oracle_success"])
            key = {(True, True): "true_accept", (True, False): "false_accept",
                   (False, True): "false_reject", (False, False): "true_reject"}[(critic, oracle)]
            counts[key] += 1
    return AuditReport(**counts)
