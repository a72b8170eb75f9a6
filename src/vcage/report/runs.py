"""Throughput and time by phase, from the runs log (``meta/vcage_runs.jsonl``: one line per run).

Each run's core time (wall time x workers) is split into physics, rendering (the critic's views
and the videos) and the rest (planning, inverse kinematics, encoding, writing, idle workers).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

PHASES = ("physics", "render", "other")


@dataclass(frozen=True)
class RunTiming:
    instruction: str
    requested: int
    accepted: int
    attempts: int
    given_up: int
    workers: int
    wall: float  # seconds
    core: float  # seconds: wall x workers
    physics: float  # seconds of core time
    render: float

    @property
    def other(self) -> float:
        return max(0.0, self.core - self.physics - self.render)

    @property
    def episodes_per_hour(self) -> float:
        return self.accepted / (self.wall / 3600) if self.wall > 0 else 0.0

    @property
    def episodes_per_core_hour(self) -> float:
        return self.accepted / (self.core / 3600) if self.core > 0 else 0.0

    def phase(self, name: str) -> float:
        return float(getattr(self, name))


def run_timing(record: dict[str, Any]) -> RunTiming:
    seconds = record.get("seconds") or {}
    return RunTiming(
        instruction=str(record.get("instruction", "")), requested=int(record.get("episodes_requested", 0)),
        accepted=int(record.get("accepted", 0)), attempts=int(record.get("attempts", 0)),
        given_up=int(record.get("given_up", 0)), workers=int(record.get("workers", 1)),
        wall=float(record.get("wall_seconds", 0.0)),
        core=float(record.get("core_seconds", record.get("wall_seconds", 0.0))),
        physics=float(seconds.get("physics", 0.0)),
        render=float(seconds.get("render", 0.0)))


def total(runs: Sequence[RunTiming]) -> RunTiming:
    """All runs as one: times and counts added (throughput over the summed wall time)."""
    wall = sum(r.wall for r in runs)
    return RunTiming(
        instruction="all runs", requested=sum(r.requested for r in runs),
        accepted=sum(r.accepted for r in runs), attempts=sum(r.attempts for r in runs),
        given_up=sum(r.given_up for r in runs), workers=max((r.workers for r in runs), default=1),
        wall=wall, core=sum(r.core for r in runs), physics=sum(r.physics for r in runs),
        render=sum(r.render for r in runs))
