"""Run one atomic-task episode: build, compose, settle, expert, and a held success check."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from vcage.config import Randomization, SimConfig
from vcage.errors import SkillError, UnstableSceneError
from vcage.scene.compose import compose
from vcage.scene.spec import SceneSpec
from vcage.scene.stability import StabilityConfig, check_stability
from vcage.sim.world import World
from vcage.skills.executor import Recording
from vcage.skills.primitives import Skills
from vcage.tasks.base import TASKS, AtomicTask, SceneConfig

SETTLE_SECONDS = 0.3


@dataclass
class EpisodeResult:
    task: str
    seed: int
    success: bool
    instruction: str
    info: dict[str, Any]
    spec: SceneSpec
    recording: Recording
    initial_state: np.ndarray
    world: World  # the world after the episode (for rendering, replay checks)
    skill_error: str | None = None


def make_task(name: str) -> AtomicTask:
    import vcage.tasks.library  # noqa: F401  (registers the built-in tasks)

    return TASKS.get(name)()


def prepare(name: str, seed: int, rand: Randomization, sim: SimConfig = SimConfig(),
            scene: SceneConfig | None = None) -> tuple[AtomicTask, World, np.random.Generator]:
    """Build and compose the task's scene for ``seed`` and let it settle.

    Unless ``scene.check`` is off, the scene is checked while it settles and an invalid one
    raises :class:`UnstableSceneError` with the reason.
    """
    task = make_task(name)
    rng = np.random.default_rng(seed)
    scene = scene or SceneConfig()
    spec = task.build(rng, rand, scene)
    world = compose(spec, sim).make_world(sim)
    if scene.check:  # settles the world as it checks it
        report = check_stability(world, StabilityConfig(settle_seconds=SETTLE_SECONDS))
        if not report.ok:
            raise UnstableSceneError(f"the scene of {name} (seed {seed}, {scene.placement} "
                                     f"placement) is not physically valid: {report.reason()}")
    else:
        world.settle(SETTLE_SECONDS)
    task.setup(world)
    return task, world, rng


def run_episode(name: str, seed: int, rand: Randomization | None = None,
                sim: SimConfig = SimConfig(), record: bool = True,
                scene: SceneConfig | None = None) -> EpisodeResult:
    """Run the scripted expert of task ``name`` on the scene of ``seed``.

    A skill that cannot plan (unreachable, no grasp) ends the episode as a failure with its
    message; a :class:`SimulationError` propagates, since an unstable rollout is not data.
    """
    rand = Randomization() if rand is None else rand
    task, world, rng = prepare(name, seed, rand, sim, scene)
    instruction = task.instruction(rng)
    initial = world.get_state()
    skills = Skills(world)
    skills.executor.record = record
    skills.executor.hooks.append(task.on_step)
    error = None
    try:
        task.expert(skills)
    except SkillError as exc:
        error = str(exc)
    success, info = held_success(task, skills)
    assert task.spec is not None
    return EpisodeResult(name, seed, success and error is None, instruction, info, task.spec,
                         skills.executor.recording, initial, world, error)


def held(skills: Skills, check: Callable[[], dict[str, Any]],
         steps: int) -> tuple[dict[str, bool], dict[str, Any]]:
    """Keep the last command for ``2 * steps`` control steps, calling ``check`` after each.

    Returns, per key of ``check``'s dict, whether its value was true on the last ``steps``
    consecutive calls, and the last dict itself: success must hold, not flicker for one frame.
    """
    streak: dict[str, int] = {}
    values: dict[str, Any] = {}
    for _ in range(steps * 2):
        skills.executor.wait(skills.world.control_dt)
        values = check()
        streak = {k: streak.get(k, 0) + 1 if v else 0 for k, v in values.items()}
    return {k: streak[k] >= steps for k in values}, values


def held_success(task: AtomicTask, skills: Skills) -> tuple[bool, dict[str, Any]]:
    """Keep the last command for a moment; success must hold on ``hold_steps`` consecutive steps."""
    holds, info = held(skills, lambda: task.evaluate(skills.world), task.hold_steps)
    return holds["success"], info
