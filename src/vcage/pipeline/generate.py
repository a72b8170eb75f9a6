"""The generation driver: plan once, then attempt episodes until enough are accepted.

Each episode gets up to ``max_attempts`` attempts with derived seeds; an accepted attempt is
rendered (videos are made by replaying the recorded simulator states, so rejected attempts cost no
video rendering) and written to the dataset atomically. Every attempt, accepted or not, is logged
with its oracle audit in ``meta/vcage_attempts.jsonl``; the funnel goes to ``stats.json``.
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

import numpy as np

from vcage.critics import ground_truth, image, vlm  # noqa: F401  (register the critics)
from vcage.critics.base import CRITICS, Critic
from vcage.data import DatasetWriter, Feature
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

    @property
    def label_noise(self) -> float:
        return self.accepted_oracle_failed / self.accepted if self.accepted else 0.0

    def to_dict(self) -> dict[str, Any]:
        hours = self.wall / 3600
        return {
            "episodes_requested": self.episodes_requested, "attempts": self.attempts,
            "accepted": self.accepted, "given_up": self.given_up, "stages": dict(self.stages),
            "rejections_by_reason": {f"{s}: {r}": n for (s, r), n in self.reasons.most_common()},
            "accepted_oracle_failed": self.accepted_oracle_failed, "label_noise": self.label_noise,
            "wall_seconds": round(self.wall, 2),
            "seconds": {"physics": round(self.timing.physics, 2), "render": round(self.timing.render, 2),
                        "attempts_total": round(self.timing.total, 2)},
            "episodes_per_hour": self.accepted / hours if hours > 0 else 0.0,
            "total_over_physics_and_render": (self.wall / (self.timing.physics + self.timing.render)
                                              if self.timing.physics + self.timing.render > 0 else None),
        }


Progress = Callable[[Funnel], None]


def generate(instruction: str, episodes: int, out: Path, cfg: GenerateConfig,
             progress: Progress | None = None, plan: Plan | None = None) -> Funnel:
    t0 = time.perf_counter()
    plan = plan or make_planner(cfg.planner).plan(instruction)
    critic: Critic | None = CRITICS.get(cfg.critic_name)() if cfg.critic_name else None
    width, height = cfg.size
    funnel = Funnel(episodes_requested=episodes)
    with DatasetWriter(out, fps=_fps(), features=FEATURES,
                       cameras={camera_key(c): (height, width) for c in cfg.cameras},
                       robot_type="franka_panda",
                       config={"generate": cfg.to_dict(), "plan": plan.model_dump(mode="json")}) as writer:
        first = writer.num_episodes
        for k in range(first, first + episodes):
            for j in range(cfg.max_attempts):
                result = attempt(plan, cfg.episode_seed(k, j), cfg, critic)
                _count(funnel, result)
                _log_attempt(out, k, j, result)
                if result.accepted:
                    _write(writer, plan, cfg, result, k, j, funnel)
                    break
            else:
                funnel.given_up += 1
            funnel.wall = time.perf_counter() - t0
            if progress is not None:
                progress(funnel)
    funnel.wall = time.perf_counter() - t0
    (out / STATS_FILE).write_text(json.dumps(funnel.to_dict(), indent=2))
    return funnel


def _fps() -> int:
    from vcage.config import SimConfig

    return int(SimConfig().control_hz)


def _count(funnel: Funnel, result: Attempt) -> None:
    funnel.attempts += 1
    funnel.stages[result.stage] += 1
    funnel.timing.add(result.timing)
    if result.accepted:
        funnel.accepted += 1
        if not result.oracle_success:
            funnel.accepted_oracle_failed += 1
    else:
        funnel.reasons[(result.stage, _reason_key(result.reason))] += 1


def _reason_key(reason: str) -> str:
    return re.sub(r"\d+(\.\d+)?", "N", reason.split(";")[0]).strip()[:90]


def _audit(result: Attempt) -> list[dict[str, Any]]:
    if result.rollout is None:
        return []
    return [{"subtask": o.index, "skill": o.skill, "description": o.description, "frames": [o.start, o.end],
             "oracle": o.oracle, "oracle_success": o.oracle_success, "skill_error": o.skill_error}
            for o in result.rollout.outcomes]


def _log_attempt(out: Path, episode: int, index: int, result: Attempt) -> None:
    record = {"episode": episode, "attempt": index, "seed": result.seed, "stage": result.stage,
              "reason": result.reason, "oracle_success": result.oracle_success,
              "audit": _audit(result),
              "verdicts": [o.verdict for o in result.rollout.outcomes] if result.rollout else []}
    with (out / ATTEMPTS_LOG).open("a") as f:
        f.write(json.dumps(record) + "\n")


def _write(writer: DatasetWriter, plan: Plan, cfg: GenerateConfig, result: Attempt, episode: int,
           index: int, funnel: Funnel) -> None:
    assert result.recording is not None and result.world is not None and result.rollout is not None
    rec = result.recording.arrays()
    frames = {
        "observation.state": np.column_stack([rec["qpos"], rec["gripper"]]).astype(np.float32),
        "observation.ee_pose": np.column_stack([rec["ee_pos"], rec["ee_quat"]]).astype(np.float32),
        "action": rec["action"].astype(np.float32),
    }
    states = np.asarray(result.recording.states)
    t0 = time.perf_counter()
    videos = _render_videos(result, states, cfg)
    funnel.timing.render += time.perf_counter() - t0
    extras = {
        "seed": result.seed, "attempt": index, "instruction": plan.instruction,
        "plan": plan.model_dump(mode="json"),
        "config": cfg.to_dict(), "scene": result.scene.to_dict() if result.scene else None,
        "subtasks": [{"index": o.index, "description": o.description, "frames": [o.start, o.end],
                      "verdict": o.verdict} for o in result.rollout.outcomes],
        "oracle_audit": _audit(result), "oracle_success": result.oracle_success,
    }
    arrays = {"states": states, "initial_state": np.asarray(result.initial_state)}
    writer.add_episode(frames, videos, task=plan.instruction, extras=extras, arrays=arrays)


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
