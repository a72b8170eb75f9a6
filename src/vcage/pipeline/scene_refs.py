"""Scene references for the subtask stage, with the ones only the pipeline can build.

``goal:<name>`` or ``goal:<name>@<seed>`` is the scene of a library goal's plan, laid out and
placed for that seed as an episode of the goal would start (context-aware placement, seeded
randomisation, no clutter). Every other reference (``task:...``, a scene_spec.json) is the subtask
stage's own (:func:`vcage.subtasks.scenes.resolve`).
"""

from __future__ import annotations

import numpy as np

from vcage.config import Randomization
from vcage.errors import ConfigError
from vcage.pipeline.plan_layout import plan_layout
from vcage.planning.goals import GOALS
from vcage.scene.instantiate import Instantiator, SceneConfig
from vcage.scene.spec import SceneSpec
from vcage.skills.reachability import reach_map
from vcage.subtasks.records import SceneRecord
from vcage.subtasks.scenes import resolve as resolve_subtask_scene
from vcage.subtasks.scenes import scene_id

PREFIX = "goal:"


def goal_scene(name: str, seed: int = 0) -> tuple[SceneRecord, SceneSpec]:
    """The placed scene of library goal ``name`` for ``seed``."""
    goal = next((g for g in GOALS if g.name == name), None)
    if goal is None:
        raise ConfigError(f"unknown goal {name!r}; goals: {', '.join(g.name for g in GOALS)}")
    plan = goal.plan(goal.phrasings[0])
    rng = np.random.default_rng(seed)
    layout = plan_layout(plan, rng, Randomization())
    spec, _ = Instantiator(SceneConfig(), reach=reach_map()).place(layout, rng)
    return SceneRecord(scene_id(spec), f"{PREFIX}{name}@{seed}", spec.to_dict()), spec


def resolve(ref: str) -> tuple[SceneRecord, SceneSpec]:
    """The scene a reference names: ``goal:<name>[@seed]``, or any reference of the subtask stage."""
    if not ref.startswith(PREFIX):
        return resolve_subtask_scene(ref)
    name, _, tail = ref[len(PREFIX):].partition("@")
    try:
        seed = int(tail) if tail else 0
    except ValueError:
        raise ConfigError(f"scene {ref!r}: the seed after '@' must be an integer") from None
    return goal_scene(name, seed)
