"""Back-fill the features newer versions write into a dataset made before them, from the simulator
states it stores, without generating anything again.

``observation.environment_state`` is the kinematics of each stored state (the episode's world is
composed again from the scene spec in its extras); ``subtask_index`` comes from the subtask frame
ranges in its extras; ``action.ee_pose`` is the forward kinematics of each frame's joint action. The
columns are added by :func:`vcage.data.columns.add_features` (crash-safe: ``meta/info.json`` commits
them last; running it again completes an interrupted run).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path

import numpy as np

from vcage.data import DatasetReader
from vcage.data.columns import add_features
from vcage.errors import DatasetError
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.features import (
    ACTION,
    ACTION_EE,
    ENVIRONMENT,
    SUBTASK,
    dataset_features,
    ee_actions,
    environment_states,
    subtask_indices,
)
from vcage.planning.schema import Plan
from vcage.scene.compose import compose
from vcage.scene.spec import SceneSpec

BACKFILLED = (ENVIRONMENT, SUBTASK, ACTION_EE)


def backfill(root: str | Path, progress: Callable[[int, int], None] | None = None) -> list[str]:
    """Add the features of :data:`BACKFILLED` the dataset lacks; returns their names (empty: none).

    DatasetError if the dataset was not made by ``vcage generate`` (no plan in ``meta/vcage.json``)
    or an episode lacks what is needed (its scene spec, subtask frames or stored states).
    """
    root = Path(root)
    reader = DatasetReader(root)
    config = reader.config or {}
    if not isinstance(config.get("plan"), dict) or not isinstance(config.get("generate"), dict):
        raise DatasetError(f"{root} was not made by `vcage generate` (its meta/vcage.json has no plan); "
                           "only generated datasets can be back-filled")
    plan = Plan.model_validate(config["plan"])
    cfg = GenerateConfig.from_dict(config["generate"])
    wanted = {k: f for k, f in dataset_features(plan).items() if k in BACKFILLED and k not in reader.features}
    if not wanted:
        return []

    def values(index: int) -> Mapping[str, np.ndarray]:
        extras = reader.extras(index)
        states = reader.arrays(index).get("states")
        scene, subtasks = extras.get("scene"), extras.get("subtasks")
        if states is None or not isinstance(scene, dict) or not isinstance(subtasks, list):
            raise DatasetError(f"episode {index} lacks its stored states, scene spec or subtask frames "
                               "(extras/); it cannot be back-filled")
        world = compose(SceneSpec.from_dict(scene), cfg.sim).make_world(cfg.sim)
        size = world.get_state().shape[0]
        if states.ndim != 2 or states.shape[1] != size:
            raise DatasetError(f"episode {index}: its stored states have {states.shape[-1]} values, the "
                               f"composed scene's state has {size}; it was made by another simulator version")
        out: dict[str, np.ndarray] = {}
        if ENVIRONMENT in wanted:
            out[ENVIRONMENT] = environment_states(world, plan, states)
        if SUBTASK in wanted:
            out[SUBTASK] = subtask_indices([s["frames"] for s in subtasks], len(states))
        if ACTION_EE in wanted:
            out[ACTION_EE] = ee_actions(world, reader.episode(index).frames[ACTION])
        return out

    add_features(root, wanted, values, progress)
    return list(wanted)
