"""Run one atomic-task episode: instantiate the scene, run the expert, judge held success."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from vcage.config import Randomization, SimConfig
from vcage.scene.instantiate import Instantiator, SceneConfig
from vcage.scene.placement import PlacementStats
from vcage.scene.spec import SceneSpec
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.skills.playback import Recording
from vcage.skills.reachability import reach_map
from vcage.tasks.base import TASKS, AtomicTask
from vcage.tasks.engine import Step, TaskGoal, run


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
    """A fresh instance of the registered task ``name`` (one per episode)."""
    return TASKS.get(name)()


def place_scene(task: AtomicTask, rng: np.random.Generator, rand: Randomization,
                scene: SceneConfig | None = None, sim: SimConfig = SimConfig()) -> tuple[Instantiator,
                                                                                        PlacementStats]:
    """Lay out ``task``'s scene and place it, without physics (sets ``task.spec``); returns the
    instantiator that realises it and the placement statistics."""
    scene = scene or SceneConfig()
    instantiator = Instantiator(scene, sim, reach_map())
    task.spec, stats = instantiator.place(task.layout_spec(rng, rand, scene.clutter), rng)
    return instantiator, stats


def prepare(name: str, seed: int, rand: Randomization, sim: SimConfig = SimConfig(),
            scene: SceneConfig | None = None) -> tuple[AtomicTask, World, np.random.Generator]:
    """Instantiate the task's scene for ``seed``: placed, composed and settled.

    Unless ``scene.check`` is off, an invalid scene raises :class:`UnstableSceneError` with the
    reason.
    """
    task = make_task(name)
    rng = np.random.default_rng(seed)
    scene = scene or SceneConfig()
    instantiator, stats = place_scene(task, rng, rand, scene, sim)
    assert task.spec is not None
    instance = instantiator.realize(task.spec, stats)
    instance.require_valid(f"{name} (seed {seed}, {scene.placement} placement)")
    task.setup(instance.world)
    return task, instance.world, rng


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
    skills.player.record = record
    outcome = run(skills, [Step(name, instruction, task.expert, TaskGoal(task, world))]).outcomes[0]
    assert task.spec is not None
    return EpisodeResult(name, seed, outcome.oracle_success, instruction, outcome.values, task.spec,
                         skills.player.recording, initial, world, outcome.skill_error)
