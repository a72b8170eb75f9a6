"""Rejection sampling of one episode: attempts with derived seeds until one is accepted.

An accepted attempt is turned into what the dataset writer needs: per-frame features, videos made
by replaying the recorded simulator states (so rejected attempts cost no video rendering), the
extras that reproduce and audit it, and the simulator states. Every attempt also gives a log record
with its oracle audit. Everything returned is plain data, so episodes can run in other processes.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from vcage.critics import Critic, make_critic
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.episode import Attempt, Timing, attempt
from vcage.pipeline.features import ee_actions, environment_states, frames_of, subtask_indices
from vcage.planning.schema import Plan
from vcage.provenance import software
from vcage.sim.render import Renderer


def camera_key(camera: str) -> str:
    return "observation.images." + camera.split("/")[-1]


@dataclass
class EpisodeData:
    """An accepted episode ready for the writer: per-frame features, videos, extras, arrays."""

    frames: dict[str, np.ndarray]
    videos: dict[str, np.ndarray]
    extras: dict[str, Any]
    arrays: dict[str, np.ndarray]


@dataclass
class EpisodeRun:
    """What one episode's attempts produced: a log record and timing per attempt, the episode
    if one was accepted (with the time its videos took to render), and what the critic saw in each
    attempt it rejected."""

    index: int
    records: list[dict[str, Any]] = field(default_factory=list)
    timings: list[Timing] = field(default_factory=list)
    episode: EpisodeData | None = None
    video_seconds: float = 0.0  # making the accepted episode's data: videos, features, extras
    video_render: float = 0.0  # ... of which rendering the videos
    critic_views: dict[tuple[int, int], bytes] = field(default_factory=dict)  # (sample, attempt) -> PNG


def sample_episode(plan: Plan, index: int, cfg: GenerateConfig, critic: Critic | None) -> EpisodeRun:
    """Attempt episode ``index`` with its derived seeds until one attempt is accepted or the bound."""
    run = EpisodeRun(index)
    for j in range(cfg.max_attempts):
        result = attempt(plan, cfg.episode_seed(index, j), cfg, critic)
        run.records.append(log_record(index, j, result))
        run.timings.append(result.timing)
        if result.critic_view is not None:
            run.critic_views[(index, j)] = result.critic_view
        if result.accepted:
            t0, made = time.perf_counter(), Timing()
            run.episode = episode_data(plan, cfg, result, run.records, made)
            run.video_seconds = time.perf_counter() - t0
            run.video_render = made.video_render
            break
    return run


def build_critic(cfg: GenerateConfig) -> Critic | None:
    """The critic ``cfg`` names, or None (Vanilla)."""
    return make_critic(cfg.critic) if cfg.critic is not None else None


def _audit(result: Attempt) -> list[dict[str, Any]]:
    if result.rollout is None:
        return []
    return [{"subtask": o.index, "skill": o.skill, "description": o.description, "frames": [o.start, o.end],
             "oracle": o.oracle, "oracle_success": o.oracle_success, "skill_error": o.skill_error}
            for o in result.rollout.outcomes]


def log_record(episode: int, index: int, result: Attempt) -> dict[str, Any]:
    """The attempt's line in ``meta/vcage_attempts.jsonl``: outcome, oracle audit, verdicts, and the
    plan's objects fused into another object where the rollout started (an unchecked scene can);
    ``codes``, only where the critic rejected it with reason codes (see :class:`~vcage.critics.Verdict`)."""
    record = {"episode": episode, "attempt": index, "seed": result.seed, "stage": result.stage,
              "reason": result.reason, "oracle_success": result.oracle_success,
              "audit": _audit(result),
              "verdicts": [o.verdict for o in result.rollout.outcomes] if result.rollout else [],
              "fused_at_start": [[a, b, round(d, 5)] for a, b, d in result.fused]}
    if result.codes:
        record["codes"] = list(result.codes)
    return record


def episode_data(plan: Plan, cfg: GenerateConfig, result: Attempt,
                 attempts: list[dict[str, Any]], timing: Timing | None = None) -> EpisodeData:
    """What the writer needs for the accepted attempt, the last of ``attempts`` (the log records of
    this episode's attempts): features, videos, extras, states. The extras carry the records, so
    the attempt log can be restored from the dataset (:mod:`.attempt_log`). ``timing``, if given,
    gets the seconds the videos took to render added to its ``video_render``."""
    assert result.recording is not None and result.world is not None and result.rollout is not None
    rec = result.recording.arrays()
    states = np.asarray(result.recording.states)
    bounds = [(o.start, o.end) for o in result.rollout.outcomes]
    frames = frames_of(rec, environment_states(result.world, plan, states),
                       subtask_indices(bounds, len(states)), ee_actions(result.world, rec["action"]))
    extras = {
        "seed": result.seed, "attempt": attempts[-1]["attempt"], "sample": attempts[-1]["episode"],
        "instruction": plan.instruction,
        "plan": plan.model_dump(mode="json"),
        "config": cfg.to_dict(), "scene": result.scene.to_dict() if result.scene else None,
        "subtasks": [{"index": o.index, "description": o.description, "frames": [o.start, o.end],
                      "verdict": o.verdict} for o in result.rollout.outcomes],
        "oracle_audit": _audit(result), "oracle_success": result.oracle_success,
        "attempts": list(attempts),
        "software": software(),
    }
    arrays = {"states": states, "initial_state": np.asarray(result.initial_state)}
    t0 = time.perf_counter()
    videos = _render_videos(result, states, cfg)
    if timing is not None:
        timing.video_render += time.perf_counter() - t0
    return EpisodeData(frames, videos, extras, arrays)


def _render_videos(result: Attempt, states: np.ndarray, cfg: GenerateConfig) -> dict[str, np.ndarray]:
    assert result.world is not None
    with Renderer(result.world, *cfg.render.size, cfg.render.mesh_detail) as renderer:
        frames = renderer.rgb_states(states, cfg.render.cameras)
    return {camera_key(c): frames[c] for c in cfg.render.cameras}
