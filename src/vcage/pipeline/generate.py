"""The generation driver: plan once, then attempt episodes until enough are accepted.

Each episode gets up to ``max_attempts`` attempts with derived seeds; an accepted attempt is
rendered (videos are made by replaying the recorded simulator states, so rejected attempts cost no
video rendering) and written to the dataset atomically. Every attempt, accepted or not, is logged
with its oracle audit in ``meta/vcage_attempts.jsonl``; the funnel goes to ``stats.json``.
"""

from __future__ import annotations

import itertools
import json
import multiprocessing
import os
import re
import time
from collections import Counter, deque
from collections.abc import Callable, Iterator
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from vcage.critics import ground_truth, image, vlm  # noqa: F401  (register the critics)
from vcage.critics.base import CRITICS, Critic
from vcage.data import DatasetWriter, Feature
from vcage.errors import ConfigError
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.episode import Attempt, Timing, attempt
from vcage.planning import make_planner
from vcage.planning.schema import Plan
from vcage.sim.render import Renderer

ATTEMPTS_LOG = "meta/vcage_attempts.jsonl"
STATS_FILE = "stats.json"
JOINTS = [f"joint{i}" for i in range(1, 8)]
FEATURES = {
    "observation.state": Feature("float32", (8,), names=[*JOINTS, "gripper_width"]),
    "observation.ee_pose": Feature("float32", (7,), names=["x", "y", "z", "qw", "qx", "qy", "qz"]),
    "action": Feature("float32", (8,), names=[*JOINTS, "gripper"]),
}


def camera_key(camera: str) -> str:
    return "observation.images." + camera.split("/")[-1]


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


@dataclass
class EpisodeData:
    """An accepted episode ready for the writer: per-frame features, videos, extras, arrays."""

    frames: dict[str, np.ndarray]
    videos: dict[str, np.ndarray]
    extras: dict[str, Any]
    arrays: dict[str, np.ndarray]


@dataclass
class EpisodeRun:
    """What one episode's attempts produced: a log record and timing per attempt, and the episode
    if one was accepted (with the time its videos took to render)."""

    index: int
    records: list[dict[str, Any]] = field(default_factory=list)
    timings: list[Timing] = field(default_factory=list)
    episode: EpisodeData | None = None
    video_seconds: float = 0.0


def generate(instruction: str, episodes: int, out: Path, cfg: GenerateConfig,
             progress: Progress | None = None, plan: Plan | None = None, workers: int = 1) -> Funnel:
    """Generate ``episodes`` accepted episodes into the dataset at ``out``; returns the funnel.

    With ``workers > 1`` episodes are attempted in that many processes; each episode's attempts
    depend only on its seeds, so the dataset is the same as with one worker.
    """
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ConfigError(f"workers must be a positive integer, got {workers!r}")
    t0 = time.perf_counter()
    plan = plan or make_planner(cfg.planner).plan(instruction)
    critic = _critic(cfg)  # built here too, so a misconfigured critic fails before any work
    width, height = cfg.size
    funnel = Funnel(episodes_requested=episodes, workers=workers)
    with DatasetWriter(out, fps=_fps(), features=FEATURES,
                       cameras={camera_key(c): (height, width) for c in cfg.cameras},
                       robot_type="franka_panda",
                       config={"generate": cfg.to_dict(), "plan": plan.model_dump(mode="json")}) as writer:
        first = writer.num_episodes
        indices = range(first, first + episodes)
        runs = (run_episode(plan, k, cfg, critic) for k in indices) if workers == 1 else \
            _in_processes(plan, cfg, indices, workers)
        for run in runs:
            _record(out, writer, plan, run, funnel)
            funnel.wall = time.perf_counter() - t0
            if progress is not None:
                progress(funnel)
    funnel.wall = time.perf_counter() - t0
    (out / STATS_FILE).write_text(json.dumps(funnel.to_dict(), indent=2))
    return funnel


def run_episode(plan: Plan, index: int, cfg: GenerateConfig, critic: Critic | None) -> EpisodeRun:
    """Attempt episode ``index`` with its derived seeds until one attempt is accepted or the bound."""
    run = EpisodeRun(index)
    for j in range(cfg.max_attempts):
        result = attempt(plan, cfg.episode_seed(index, j), cfg, critic)
        run.records.append(_log_record(index, j, result))
        run.timings.append(result.timing)
        if result.accepted:
            t0 = time.perf_counter()
            run.episode = _episode_data(plan, cfg, result, j)
            run.video_seconds = time.perf_counter() - t0
            break
    return run


def _critic(cfg: GenerateConfig) -> Critic | None:
    return CRITICS.get(cfg.critic_name)() if cfg.critic_name else None


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


# Worker processes: each builds its own critic once, then runs whole episodes.
_WORKER: dict[str, Any] = {}


def _start_worker(plan: Plan, cfg: GenerateConfig) -> None:
    os.environ.setdefault("LP_NUM_THREADS", "1")  # one rasteriser thread: a worker is one core
    _WORKER.update(plan=plan, cfg=cfg, critic=_critic(cfg))


def _worker_episode(index: int) -> EpisodeRun:
    return run_episode(_WORKER["plan"], index, _WORKER["cfg"], _WORKER["critic"])


def _in_processes(plan: Plan, cfg: GenerateConfig, indices: range, workers: int) -> Iterator[EpisodeRun]:
    """Episodes from ``workers`` processes, yielded in index order (a few run ahead)."""
    context = multiprocessing.get_context("spawn")  # fresh processes: no GL context or thread is forked
    with ProcessPoolExecutor(workers, mp_context=context, initializer=_start_worker,
                             initargs=(plan, cfg)) as pool:
        todo = iter(indices)
        pending = deque(pool.submit(_worker_episode, k) for k in itertools.islice(todo, 2 * workers))
        try:
            while pending:
                run = pending.popleft().result()
                for k in itertools.islice(todo, 1):
                    pending.append(pool.submit(_worker_episode, k))
                yield run
        finally:
            for future in pending:
                future.cancel()


def _fps() -> int:
    from vcage.config import SimConfig

    return int(SimConfig().control_hz)


def _count(funnel: Funnel, record: dict[str, Any], timing: Timing) -> None:
    funnel.attempts += 1
    funnel.stages[record["stage"]] += 1
    funnel.timing.add(timing)
    if record["stage"] == "accepted":
        funnel.accepted += 1
        if not record["oracle_success"]:
            funnel.accepted_oracle_failed += 1
    else:
        funnel.reasons[(record["stage"], _reason_key(record["reason"]))] += 1


def _reason_key(reason: str) -> str:
    return re.sub(r"\d+(\.\d+)?", "N", reason.split(";")[0]).strip()[:90]


def _audit(result: Attempt) -> list[dict[str, Any]]:
    if result.rollout is None:
        return []
    return [{"subtask": o.index, "skill": o.skill, "description": o.description, "frames": [o.start, o.end],
             "oracle": o.oracle, "oracle_success": o.oracle_success, "skill_error": o.skill_error}
            for o in result.rollout.outcomes]


def _log_record(episode: int, index: int, result: Attempt) -> dict[str, Any]:
    return {"episode": episode, "attempt": index, "seed": result.seed, "stage": result.stage,
            "reason": result.reason, "oracle_success": result.oracle_success,
            "audit": _audit(result),
            "verdicts": [o.verdict for o in result.rollout.outcomes] if result.rollout else []}


def _episode_data(plan: Plan, cfg: GenerateConfig, result: Attempt, index: int) -> EpisodeData:
    assert result.recording is not None and result.world is not None and result.rollout is not None
    rec = result.recording.arrays()
    frames = {
        "observation.state": np.column_stack([rec["qpos"], rec["gripper"]]).astype(np.float32),
        "observation.ee_pose": np.column_stack([rec["ee_pos"], rec["ee_quat"]]).astype(np.float32),
        "action": rec["action"].astype(np.float32),
    }
    states = np.asarray(result.recording.states)
    extras = {
        "seed": result.seed, "attempt": index, "instruction": plan.instruction,
        "plan": plan.model_dump(mode="json"),
        "config": cfg.to_dict(), "scene": result.scene.to_dict() if result.scene else None,
        "subtasks": [{"index": o.index, "description": o.description, "frames": [o.start, o.end],
                      "verdict": o.verdict} for o in result.rollout.outcomes],
        "oracle_audit": _audit(result), "oracle_success": result.oracle_success,
    }
    arrays = {"states": states, "initial_state": np.asarray(result.initial_state)}
    return EpisodeData(frames, _render_videos(result, states, cfg), extras, arrays)


def _render_videos(result: Attempt, states: np.ndarray, cfg: GenerateConfig) -> dict[str, np.ndarray]:
    world = result.world
    assert world is not None
    width, height = cfg.size
    out = {camera_key(c): np.empty((len(states), height, width, 3), np.uint8) for c in cfg.cameras}
    with Renderer(world, width, height) as renderer:
        for i, state in enumerate(states):
            world.set_state(state)
            for cam in cfg.cameras:
                out[camera_key(cam)][i] = renderer.rgb(cam)
    return out
