"""The generation driver: plan once, sample episodes on an executor, write what is accepted.

Each episode gets up to ``max_attempts`` attempts with derived seeds (:mod:`.sampling`); an
accepted one is written to the dataset atomically, in episode order. Every attempt, accepted or
not, is logged with its oracle audit in ``meta/vcage_attempts.jsonl``; the funnel goes to
``stats.json`` (paths in :mod:`vcage.data.layout`).
"""

from __future__ import annotations

import json
import re
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from vcage.data import DatasetWriter
from vcage.data.layout import ATTEMPTS_LOG, FUNNEL_PATH
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.episode import Timing
from vcage.pipeline.executors import make_executor
from vcage.pipeline.sampling import FEATURES, EpisodeRun, build_critic, camera_key
from vcage.pipeline.stage import Stage
from vcage.planning import make_planner
from vcage.planning.schema import Plan


@dataclass
class Funnel:
    """How a run went: attempts by outcome stage and reason, accepted episodes, time."""

    episodes_requested: int = 0
    attempts: int = 0
    stages: Counter = field(default_factory=Counter)
    reasons: Counter = field(default_factory=Counter)
    accepted: int = 0
    accepted_oracle_failed: int = 0  # label noise: accepted, yet the oracle says a subtask failed
    given_up: int = 0  # episodes that used up their attempts
    timing: Timing = field(default_factory=Timing)
    wall: float = 0.0
    workers: int = 1  # processes attempting episodes; core time is wall * workers

    @property
    def label_noise(self) -> float:
        return self.accepted_oracle_failed / self.accepted if self.accepted else 0.0

    def to_dict(self) -> dict[str, Any]:
        hours = self.wall / 3600
        core_seconds = self.wall * self.workers
        busy = self.timing.physics + self.timing.render
        return {
            "episodes_requested": self.episodes_requested, "attempts": self.attempts,
            "accepted": self.accepted, "given_up": self.given_up, "stages": dict(self.stages),
            "rejections_by_reason": {f"{s}: {r}": n for (s, r), n in self.reasons.most_common()},
            "accepted_oracle_failed": self.accepted_oracle_failed, "label_noise": self.label_noise,
            "wall_seconds": round(self.wall, 2), "workers": self.workers,
            "core_seconds": round(core_seconds, 2),
            "seconds": {"physics": round(self.timing.physics, 2), "render": round(self.timing.render, 2),
                        "attempts_total": round(self.timing.total, 2)},
            "episodes_per_hour": self.accepted / hours if hours > 0 else 0.0,
            "episodes_per_core_hour": self.accepted / (core_seconds / 3600) if core_seconds > 0 else 0.0,
            # core time (idle workers included) over the time spent in physics and rendering
            "total_over_physics_and_render": core_seconds / busy if busy > 0 else None,
        }


Progress = Callable[[Funnel], None]


def generate(instruction: str, episodes: int, out: Path | str, cfg: GenerateConfig,
             progress: Progress | None = None, plan: Plan | None = None) -> Funnel:
    """Generate ``episodes`` accepted episodes into the dataset at ``out``; returns the funnel.

    ``cfg.executor`` runs up to ``cfg.executor.workers`` episodes at once (see
    :mod:`vcage.pipeline.executors`). Each episode's attempts depend only on its seeds, so the
    dataset is the same for any executor and number of workers. The resolved configuration
    (model endpoints included, keys never) is stored with the dataset and every episode.
    """
    out = Path(out)
    cfg = cfg.resolved()
    pool = make_executor(cfg.executor)  # checks the arguments before any work
    t0 = time.perf_counter()
    plan = plan or make_planner(cfg.planner).plan(instruction)
    critic = build_critic(cfg)  # a misconfigured critic (e.g. no API key) fails here, before any work
    width, height = cfg.render.size
    funnel = Funnel(episodes_requested=episodes, workers=cfg.executor.workers)
    with DatasetWriter(out, fps=int(cfg.sim.control_hz), features=FEATURES,
                       cameras={camera_key(c): (height, width) for c in cfg.render.cameras},
                       robot_type="franka_panda",
                       config={"generate": cfg.data_dict(), "plan": plan.model_dump(mode="json")}) as writer:
        first = writer.num_episodes
        for run in pool.runs(plan, cfg, range(first, first + episodes), critic):
            _record(out, writer, plan, run, funnel)
            funnel.wall = time.perf_counter() - t0
            if progress is not None:
                progress(funnel)
    funnel.wall = time.perf_counter() - t0
    (out / FUNNEL_PATH).write_text(json.dumps(funnel.to_dict(), indent=2))
    return funnel


def _record(out: Path, writer: DatasetWriter, plan: Plan, run: EpisodeRun, funnel: Funnel) -> None:
    """Log the run's attempts, count them in the funnel, and write its episode if it has one."""
    with (out / ATTEMPTS_LOG).open("a") as f:
        for record in run.records:
            f.write(json.dumps(record) + "\n")
    for record, timing in zip(run.records, run.timings, strict=True):
        _count(funnel, record, timing)
    funnel.timing.render += run.video_seconds
    if run.episode is None:
        funnel.given_up += 1
        return
    ep = run.episode
    writer.add_episode(ep.frames, ep.videos, task=plan.instruction, extras=ep.extras, arrays=ep.arrays)


def _count(funnel: Funnel, record: dict[str, Any], timing: Timing) -> None:
    funnel.attempts += 1
    funnel.stages[record["stage"]] += 1
    funnel.timing.add(timing)
    if record["stage"] == Stage.ACCEPTED:
        funnel.accepted += 1
        if not record["oracle_success"]:
            funnel.accepted_oracle_failed += 1
    else:
        funnel.reasons[(record["stage"], _reason_key(record["reason"]))] += 1


def _reason_key(reason: str) -> str:
    return re.sub(r"\d+(\.\d+)?", "N", reason.split(";")[0]).strip()[:90]


