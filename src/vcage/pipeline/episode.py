"""One attempt at an episode: scene, execution with a critic after every subtask, oracle audit.

An attempt ends in one stage: ``placement`` (the layout could not be placed), ``scene`` (the
placed scene failed the physics check), ``skill`` (a skill could not plan), ``physics`` (the
simulation became unstable), ``critic`` (a subtask was rejected), or ``accepted``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from vcage.critics.base import Critic, Observation, View
from vcage.errors import PlacementError, SimulationError
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.rollout import Rollout, SubtaskOutcome, run_plan
from vcage.pipeline.scene import plan_layout
from vcage.planning.schema import Plan, Subtask
from vcage.scene.compose import compose
from vcage.scene.placement import place
from vcage.scene.spec import SceneSpec
from vcage.scene.stability import StabilityConfig, check_stability
from vcage.sim.render import Renderer
from vcage.sim.world import World
from vcage.skills.executor import Executor, Recording
from vcage.skills.primitives import Skills
from vcage.skills.reach import reach_map

SETTLE_SECONDS = 0.3


@dataclass
class Timing:
    """Wall time by activity, to relate the total to physics and rendering."""

    physics: float = 0.0
    render: float = 0.0
    total: float = 0.0

    def add(self, other: Timing) -> None:
        self.physics += other.physics
        self.render += other.render
        self.total += other.total


@dataclass
class Attempt:
    seed: int
    stage: str  # placement | scene | skill | physics | critic | accepted
    reason: str
    scene: SceneSpec | None = None
    rollout: Rollout | None = None
    recording: Recording | None = None
    world: World | None = None
    initial_state: np.ndarray | None = None
    timing: Timing = field(default_factory=Timing)

    @property
    def accepted(self) -> bool:
        return self.stage == "accepted"

    @property
    def oracle_success(self) -> bool:
        return bool(self.rollout and self.rollout.aborted_at is None and self.rollout.oracle_success
                    and len(self.rollout.outcomes) > 0)


def attempt(plan: Plan, seed: int, cfg: GenerateConfig, critic: Critic | None) -> Attempt:
    t_start = time.perf_counter()
    timing = Timing()
    result = _attempt(plan, seed, cfg, critic, timing)
    timing.total = time.perf_counter() - t_start
    result.timing = timing
    return result


def _attempt(plan: Plan, seed: int, cfg: GenerateConfig, critic: Critic | None, timing: Timing) -> Attempt:
    rng = np.random.default_rng(seed)
    layout = plan_layout(plan, rng, cfg.randomization, cfg.clutter)
    try:
        scene = place(layout, rng, cfg.placement_method, reach=reach_map()).scene
    except PlacementError as exc:
        return Attempt(seed, "placement", str(exc))
    try:
        world = compose(scene).make_world()
    except SimulationError as exc:
        return Attempt(seed, "physics", str(exc), scene)
    try:
        return _execute(plan, seed, cfg, critic, timing, scene, world)
    finally:
        timing.physics += world.physics_seconds


def _execute(plan: Plan, seed: int, cfg: GenerateConfig, critic: Critic | None, timing: Timing,
             scene: SceneSpec, world: World) -> Attempt:
    try:
        if cfg.check_scene:
            report = check_stability(world, StabilityConfig(settle_seconds=SETTLE_SECONDS))
            if not report.ok:
                return Attempt(seed, "scene", report.reason(), scene)
        else:
            world.settle(SETTLE_SECONDS)
        initial = world.get_state()
        skills = Skills(world, Executor(world, record_states=True))
        renderer = Renderer(world, *cfg.critic_size) if critic is not None and critic.needs_views else None
        try:
            judge = Judge(world, plan, critic, renderer, timing) if critic is not None else None
            if judge is not None:
                judge.skills_recording = skills.executor.recording
            rollout, skills = run_plan(world, plan, skills, judge,
                                       on_subtask_start=judge.start if judge else None)
        finally:
            if renderer is not None:
                renderer.close()
    except SimulationError as exc:
        return Attempt(seed, "physics", str(exc), scene)
    out = Attempt(seed, "accepted", "", scene, rollout, skills.executor.recording, world, initial)
    if rollout.aborted_at is not None:
        last = rollout.outcomes[-1]
        if last.skill_error is not None:
            out.stage, out.reason = "skill", last.skill_error
        else:
            verdict = last.verdict or {}
            out.stage, out.reason = "critic", f"subtask {last.index + 1}: {verdict.get('reason', '')}"
    return out


class Judge:
    """Renders the views a critic needs before and after each subtask and asks it."""

    def __init__(self, world: World, plan: Plan, critic: Critic, renderer: Renderer | None,
                 timing: Timing) -> None:
        self.world, self.plan, self.critic = world, plan, critic
        self.renderer, self.timing = renderer, timing
        self._before: dict[str, View] = {}
        self.skills_recording: Recording | None = None

    def _views(self) -> dict[str, View]:
        if self.renderer is None:
            return {}
        t0 = time.perf_counter()
        views = {cam: View(self.renderer.rgb(cam), self.renderer.segmentation(cam),
                           self.renderer.depth(cam) if cam in DEPTH_CAMERAS else None)
                 for cam in CRITIC_CAMERAS}
        self.timing.render += time.perf_counter() - t0
        return views

    def start(self, index: int, subtask: Subtask) -> None:
        self._before = self._views()

    def __call__(self, outcome: SubtaskOutcome) -> dict[str, Any]:
        obs = Observation(subtask=self.plan.subtasks[outcome.index], labels=tuple(self.world.object_names),
                          before=self._before, after=self._views(), during=self._deepest(outcome),
                          oracle=outcome.oracle)
        return self.critic.judge(obs).to_dict()

    def _deepest(self, outcome: SubtaskOutcome) -> dict[str, View]:
        """Views of the recorded frame where the hand was lowest during the subtask (e.g. a press).

        The frame is chosen from proprioception (the hand's height), as on a real robot.
        """
        rec = self.skills_recording
        if self.renderer is None or rec is None or outcome.end <= outcome.start or not rec.states:
            return {}
        heights = [p[2] for p in rec.ee_pos[outcome.start:outcome.end]]
        frame = outcome.start + int(np.argmin(heights))
        now = self.world.get_state()
        self.world.set_state(rec.states[frame])
        try:
            return self._views()
        finally:
            self.world.set_state(now)


CRITIC_CAMERAS = ("top", "front")  # the views a critic gets: top-down (orthographic) and front
DEPTH_CAMERAS = ("front",)  # ... with depth where the camera is perspective (RGB-D)
