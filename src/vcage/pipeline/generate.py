"""The generation driver: plan once, sample episodes on an executor, write what is accepted.

Each episode gets up to ``max_attempts`` attempts with derived seeds (:mod:`.sampling`); an
accepted one is written to the dataset atomically, in episode order. Every attempt, accepted or
not, is logged with its oracle audit (:mod:`.attempt_log`); each run's funnel is appended to
``meta/vcage_runs.jsonl`` (paths in :mod:`vcage.data.layout`). Nothing is written before the first
episode of a new dataset commits.

A rerun continues where the dataset's attempts stopped (new sample indices, never a repeat of an
episode it holds), after reconciling the attempt log with what a crash may have left; with
``total=True`` it makes the dataset hold ``episodes`` episodes, completing an interrupted run.
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from vcage.data import DatasetReader, DatasetWriter
from vcage.data.files import NO_SPACE, no_space
from vcage.data.layout import ATTEMPTS_LOG, RUNS_LOG
from vcage.errors import ConfigError, VcageError
from vcage.pipeline import attempt_log, critic_views
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.episode import Timing
from vcage.pipeline.executors import make_executor
from vcage.pipeline.features import dataset_features
from vcage.pipeline.job import build_job
from vcage.pipeline.sampling import EpisodeRun, build_critic, camera_key
from vcage.pipeline.stage import Stage
from vcage.planning.schema import Plan
from vcage.provenance import software


@dataclass
class Funnel:
    """How a run went: attempts by outcome stage and reason, accepted episodes, time."""

    episodes_requested: int = 0
    dataset_episodes: int = 0  # episodes the dataset holds after the run
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
            "episodes_requested": self.episodes_requested, "dataset_episodes": self.dataset_episodes,
            "attempts": self.attempts,
            "accepted": self.accepted, "given_up": self.given_up, "stages": dict(self.stages),
            "rejections_by_reason": {f"{s}: {r}": n for (s, r), n in self.reasons.most_common()},
            "accepted_oracle_failed": self.accepted_oracle_failed, "label_noise": self.label_noise,
            "wall_seconds": round(self.wall, 2), "workers": self.workers,
            "core_seconds": round(core_seconds, 2),
            # physics: the robot's control steps; render: critic views + videos; attempts_total:
            # the attempts' wall time; then every phase of :data:`.episode.PHASES` (physics again)
            "seconds": {"physics": round(self.timing.physics, 2), "render": round(self.timing.render, 2),
                        "attempts_total": round(self.timing.total, 2),
                        **{name: round(value, 3) for name, value in self.timing.phases().items()}},
            "episodes_per_hour": self.accepted / hours if hours > 0 else 0.0,
            "episodes_per_core_hour": self.accepted / (core_seconds / 3600) if core_seconds > 0 else 0.0,
            # core time (idle workers included) over the time spent in physics and rendering
            "total_over_physics_and_render": core_seconds / busy if busy > 0 else None,
        }


Progress = Callable[[Funnel], None]


def generate(instruction: str, episodes: int, out: Path | str, cfg: GenerateConfig,
             progress: Progress | None = None, plan: Plan | None = None, total: bool = False) -> Funnel:
    """Generate ``episodes`` more accepted episodes into the dataset at ``out`` (``total``: until it
    holds ``episodes``); returns the run's funnel.

    ``cfg.executor`` runs up to ``cfg.executor.workers`` episodes at once (see
    :mod:`vcage.pipeline.executors`). Each episode's attempts depend only on its seeds, so the
    dataset is the same for any executor and number of workers. The resolved configuration
    (model endpoints included, keys never) is stored with the dataset and every episode. Without
    ``plan``, the instruction is planned and grounded on ``cfg``'s scene source
    (:func:`~vcage.pipeline.job.build_job`).
    """
    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < (0 if total else 1):
        raise ConfigError(f"episodes must be an integer >= {0 if total else 1}, got {episodes!r}")
    out = Path(out)
    cfg = cfg.resolved()
    pool = make_executor(cfg.executor)  # checks the arguments before any work
    t0 = time.perf_counter()
    if plan is None:  # the plan of the instruction on the configuration's scene source
        job = build_job(cfg, instruction)
        plan, cfg = job.plan, job.cfg
    planning = time.perf_counter() - t0
    critic = build_critic(cfg)  # a misconfigured critic (e.g. no API key) fails here, before any work
    if critic is not None:
        critic.preflight()  # an unreachable endpoint or unserved model, before any simulation
    width, height = cfg.render.size
    funnel = Funnel(workers=cfg.executor.workers)
    funnel.timing.planning = planning
    with DatasetWriter(out, fps=int(cfg.sim.control_hz), features=dataset_features(plan),
                       cameras={camera_key(c): (height, width) for c in cfg.render.cameras},
                       robot_type="franka_panda",
                       config={"generate": cfg.data_dict(), "plan": plan.model_dump(mode="json")}) as writer:
        log = _Log(out, writer)
        funnel.episodes_requested = max(0, episodes - writer.num_episodes) if total else episodes
        first = log.next_sample
        if progress is not None:
            progress(funnel)  # everything is checked: the episodes start
        ended = "complete"
        try:
            for run in pool.runs(plan, cfg, range(first, first + funnel.episodes_requested), critic):
                _record(writer, log, plan, run, funnel)
                funnel.wall = time.perf_counter() - t0
                if progress is not None:
                    progress(funnel)
        except KeyboardInterrupt:
            ended = "interrupted"
            raise
        except VcageError as exc:  # e.g. the critic's endpoint went away mid-run
            ended = f"failed: {exc}"
            raise
        except OSError as exc:
            if exc.errno not in NO_SPACE:
                raise
            ended = f"failed: {exc}"  # the attempt log could not take an episode's lines: reconciled later
            raise no_space(out, exc, writer.num_episodes) from exc
        finally:  # the committed episodes are intact whatever ended the run: its entry says how it ended
            funnel.dataset_episodes = writer.num_episodes
            funnel.wall = time.perf_counter() - t0
            if writer.num_episodes:
                entry = {"instruction": plan.instruction, **funnel.to_dict(), "ended": ended,
                         "software": software()}
                if critic is not None:  # which rules judged this run's episodes
                    entry["critic"] = {"version": critic.version(), "rules": critic.rules()}
                try:
                    attempt_log.append(out / RUNS_LOG, [entry])
                except OSError:  # e.g. the disk that ended the run is still full: its error says so
                    if ended == "complete":
                        raise
    return funnel


class _Log:
    """The dataset's attempt log, reconciled when opened; lines wait in memory until the dataset
    exists (its first episode committed), so a run that commits nothing writes nothing."""

    def __init__(self, out: Path, writer: DatasetWriter) -> None:
        self.path, self.writer = out / ATTEMPTS_LOG, writer
        committed = []
        if writer.num_episodes:
            reader = DatasetReader(out)
            committed = [reader.extras(i) for i in range(reader.num_episodes)]
        self.next_sample = attempt_log.reconcile(self.path, committed)
        self.pending: list[dict[str, Any]] = []
        self.views: dict[tuple[int, int], bytes] = {}

    def add(self, records: list[dict[str, Any]], views: dict[tuple[int, int], bytes]) -> None:
        """Log ``records``, with the critic's views of the rejected ones (stored first)."""
        self.pending += records
        self.views.update(views)
        if self.writer.num_episodes:
            critic_views.write(self.writer.root, self.views)
            attempt_log.append(self.path, self.pending)
            self.pending, self.views = [], {}


def _record(writer: DatasetWriter, log: _Log, plan: Plan, run: EpisodeRun, funnel: Funnel) -> None:
    """Count the run's attempts in the funnel, commit its episode if it has one, then log them."""
    for record, timing in zip(run.records, run.timings, strict=True):
        _count(funnel, record, timing)
    funnel.timing.video_render += run.video_render
    funnel.timing.features += max(0.0, run.video_seconds - run.video_render)
    if run.episode is None:
        funnel.given_up += 1
    else:
        ep = run.episode
        seconds: dict[str, float] = {}
        t0 = time.perf_counter()
        writer.add_episode(ep.frames, ep.videos, task=plan.instruction, extras=ep.extras, arrays=ep.arrays,
                           timings=seconds)
        encoding = seconds.get("encode", 0.0)
        funnel.timing.encoding += encoding
        funnel.timing.writing += max(0.0, time.perf_counter() - t0 - encoding)
    log.add(run.records, run.critic_views)


def _count(funnel: Funnel, record: dict[str, Any], timing: Timing) -> None:
    funnel.attempts += 1
    funnel.stages[record["stage"]] += 1
    funnel.timing.add(timing)
    if record["stage"] == Stage.ACCEPTED:
        funnel.accepted += 1
        if not record["oracle_success"]:
            funnel.accepted_oracle_failed += 1
    else:
        funnel.reasons[(record["stage"], attempt_log.rejection_group(record))] += 1
