"""One attempt at an episode: scene, execution with a critic after every subtask, oracle audit.

An attempt ends in one :class:`~vcage.pipeline.stage.Stage`: the layout could not be placed, the
placed scene failed the physics check, a skill could not plan, the simulation became unstable, the
critic rejected a subtask, or it was accepted.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, fields

import numpy as np

from vcage.critics.base import Critic
from vcage.errors import PlacementError, SimulationError, VcageError
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.critic_views import sheet_png
from vcage.pipeline.features import objects_of
from vcage.pipeline.plan_layout import episode_scene, plan_layout
from vcage.pipeline.rollout import Rollout, run_plan
from vcage.pipeline.stage import Stage
from vcage.planning.schema import Plan
from vcage.scene.compose import compose
from vcage.scene.instantiate import Instantiator, SceneInstance
from vcage.scene.spec import SceneSpec
from vcage.scene.stability import StabilityConfig, fused
from vcage.sim.render import Renderer
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.skills.playback import Player, Recording
from vcage.skills.reachability import reach_map
from vcage.skills.recovery import Perturbation, move_start
from vcage.tasks.verifier import Verifier

# Where a run's time goes, phase by phase, in the order an episode meets them. An attempt fills
# placement .. critic_judge; the driver adds planning (once per run) and what an accepted episode
# costs after acceptance: video rendering, the per-frame features, video encoding and writing.
PHASES = ("planning", "placement", "compose", "scene_check", "physics", "critic_views", "critic_judge",
          "video_render", "features", "encoding", "writing")


@dataclass
class Timing:
    """Wall time (seconds) by phase, measured where each happens, and the total.

    ``physics`` is the robot's control steps (``mj_step`` while acting); the settling of the scene
    check is part of ``scene_check``, compiling the scene is ``compose``. ``total`` is an attempt's
    wall time (for a run: the attempts' sum). Timings never enter the dataset's data files.
    """

    planning: float = 0.0
    placement: float = 0.0
    compose: float = 0.0
    scene_check: float = 0.0
    physics: float = 0.0
    critic_views: float = 0.0
    critic_judge: float = 0.0
    video_render: float = 0.0
    features: float = 0.0
    encoding: float = 0.0
    writing: float = 0.0
    total: float = 0.0

    @property
    def render(self) -> float:
        """All rendering: the critic's views and the videos."""
        return self.critic_views + self.video_render

    def phases(self) -> dict[str, float]:
        return {name: getattr(self, name) for name in PHASES}

    def add(self, other: Timing) -> None:
        for f in fields(self):
            setattr(self, f.name, getattr(self, f.name) + getattr(other, f.name))


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
    # pairs of objects (one the plan's) interpenetrating deeper than the scene check's bound where
    # the rollout started (an unchecked scene, as Vanilla's, can start so): (a, b, depth in metres)
    fused: tuple[tuple[str, str, float], ...] = ()
    timing: Timing = field(default_factory=Timing)
    critic_view: bytes | None = None  # PNG of the views the critic rejected (:mod:`.critic_views`)
    codes: tuple[str, ...] = ()  # the critic's reason codes for its rejection (its verdict's ``codes``)

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
    clock = time.perf_counter
    t0 = clock()
    rng = np.random.default_rng(seed)
    try:
        scene = cfg.synthesized if cfg.synthesis is None else episode_scene(plan, cfg.synthesis, seed)
    except VcageError as exc:  # no scene came out of synthesis, or not the plan's
        timing.placement += clock() - t0
        return Attempt(seed, Stage.PLACEMENT, f"synthesis: {exc}")
    layout = plan_layout(plan, rng, cfg.randomization, cfg.scene.clutter, scene=scene)
    instantiator = Instantiator(cfg.scene, cfg.sim, reach_map())
    try:
        spec, stats = instantiator.place(layout, rng)
    except PlacementError as exc:
        return Attempt(seed, Stage.PLACEMENT, str(exc))
    finally:
        timing.placement += clock() - t0
    t0 = clock()
    try:
        # Compiled here into compose's model cache, which realize() then finds: the compile and the
        # scene check (settling, stability) are timed apart. The model is the same either way.
        compose(spec, cfg.sim)
        t1 = clock()
        timing.compose += t1 - t0
        try:
            instance = instantiator.realize(spec, stats)
        finally:
            timing.scene_check += clock() - t1
    except SimulationError as exc:
        return Attempt(seed, Stage.PHYSICS, str(exc), spec)
    settled = instance.world.physics_seconds
    try:
        return _execute(plan, seed, cfg, critic, timing, instance)
    finally:
        timing.physics += instance.world.physics_seconds - settled


def _fused_at(world: World, state: np.ndarray, plan: Plan) -> tuple[tuple[str, str, float], ...]:
    """The plan's objects fused into another object in ``state`` (see :func:`~vcage.scene.stability.fused`),
    read after the rollout so that it runs as it would unread; ``world`` is left as it ended."""
    end = world.get_state()
    world.set_state(state)
    pairs = fused(world, frozenset(objects_of(plan)), StabilityConfig().penetration)
    world.set_state(end)
    return pairs


def _execute(plan: Plan, seed: int, cfg: GenerateConfig, critic: Critic | None, timing: Timing,
             instance: SceneInstance) -> Attempt:
    scene, world = instance.spec, instance.world
    if not instance.valid:
        assert instance.stability is not None
        return Attempt(seed, Stage.SCENE, instance.stability.reason(), scene)
    try:
        perturbation = None
        if cfg.recovery is not None and cfg.recovery.active:
            perturbation = Perturbation(cfg.recovery, seed)
            move_start(world, perturbation)
        initial = world.get_state()
        skills = Skills(world, Player(world, record_states=True, perturbation=perturbation))
        t0 = time.perf_counter()
        renderer = (Renderer(world, *cfg.render.critic_size, cfg.render.mesh_detail)
                    if critic is not None and critic.needs_views else None)
        timing.critic_views += time.perf_counter() - t0
        verifier = None
        try:
            verifier = (Verifier(world, plan.subtasks, critic, renderer, skills.player.recording, timing)
                        if critic is not None else None)
            rollout = run_plan(world, plan, skills, verifier)
        finally:
            if renderer is not None:
                t0 = time.perf_counter()
                renderer.close()
                timing.critic_views += time.perf_counter() - t0
    except SimulationError as exc:
        return Attempt(seed, Stage.PHYSICS, str(exc), scene)
    out = Attempt(seed, Stage.ACCEPTED, "", scene, rollout, skills.player.recording, world, initial,
                  _fused_at(world, initial, plan))
    if rollout.aborted_at is not None:
        last = rollout.outcomes[-1]
        if last.skill_error is not None:
            out.stage, out.reason = Stage.SKILL, last.skill_error
        else:
            verdict = last.verdict or {}
            out.stage, out.reason = Stage.CRITIC, f"subtask {last.index + 1}: {verdict.get('reason', '')}"
            out.codes = tuple(verdict.get("codes", ()))
            out.critic_view = sheet_png(verifier.rejected_views) if verifier is not None else None
    return out
