"""One attempt at an episode: scene, execution with a critic after every subtask, oracle audit.

An attempt ends in one :class:`~vcage.pipeline.stage.Stage`: the layout could not be placed, the
placed scene failed the physics check, a skill could not plan, the simulation became unstable, the
critic rejected a subtask, or it was accepted.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from vcage.critics.base import Critic
from vcage.errors import PlacementError, SimulationError
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.plan_layout import plan_layout
from vcage.pipeline.rollout import Rollout, run_plan
from vcage.pipeline.stage import Stage
from vcage.pipeline.verifier import Verifier
from vcage.planning.schema import Plan
from vcage.scene.instantiate import Instantiator, SceneInstance
from vcage.scene.spec import SceneSpec
from vcage.sim.render import Renderer
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.skills.playback import Player, Recording
from vcage.skills.reachability import reach_map


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
    stage: Stage
    reason: str
    scene: SceneSpec | None = None
    rollout: Rollout | None = None
    recording: Recording | None = None
    world: World | None = None
    initial_state: np.ndarray | None = None
    timing: Timing = field(default_factory=Timing)

    @property
    def accepted(self) -> bool:
        return self.stage is Stage.ACCEPTED

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
    layout = plan_layout(plan, rng, cfg.randomization, cfg.scene.clutter)
    instantiator = Instantiator(cfg.scene, cfg.sim, reach_map())
    try:
        spec, stats = instantiator.place(layout, rng)
    except PlacementError as exc:
        return Attempt(seed, Stage.PLACEMENT, str(exc))
    try:
        instance = instantiator.realize(spec, stats)
    except SimulationError as exc:
        return Attempt(seed, Stage.PHYSICS, str(exc), spec)
    try:
        return _execute(plan, seed, cfg, critic, timing, instance)
    finally:
        timing.physics += instance.world.physics_seconds


def _execute(plan: Plan, seed: int, cfg: GenerateConfig, critic: Critic | None, timing: Timing,
             instance: SceneInstance) -> Attempt:
    scene, world = instance.spec, instance.world
    if not instance.valid:
        assert instance.stability is not None
        return Attempt(seed, Stage.SCENE, instance.stability.reason(), scene)
    try:
        initial = world.get_state()
        skills = Skills(world, Player(world, record_states=True))
        renderer = (Renderer(world, *cfg.render.critic_size)
                    if critic is not None and critic.needs_views else None)
        try:
            verifier = (Verifier(world, plan, critic, renderer, skills.player.recording, timing)
                        if critic is not None else None)
            rollout = run_plan(world, plan, skills, verifier)
        finally:
            if renderer is not None:
                renderer.close()
    except SimulationError as exc:
        return Attempt(seed, Stage.PHYSICS, str(exc), scene)
    out = Attempt(seed, Stage.ACCEPTED, "", scene, rollout, skills.player.recording, world, initial)
    if rollout.aborted_at is not None:
        last = rollout.outcomes[-1]
        if last.skill_error is not None:
            out.stage, out.reason = Stage.SKILL, last.skill_error
        else:
            verdict = last.verdict or {}
            out.stage, out.reason = Stage.CRITIC, f"subtask {last.index + 1}: {verdict.get('reason', '')}"
    return out
