"""An episode's videos rendered again from what its dataset stores: the scene spec and generation
config in its extras, and its simulator states. ``vcage verify --repair`` uses it to keep an episode
whose only damage is in its videos (:mod:`vcage.data.compact` keeps the result only where the
encoded frames come out identical to those written)."""

from __future__ import annotations

from typing import Any

import numpy as np

from vcage.errors import DatasetError, VcageError
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.sampling import camera_key
from vcage.scene.compose import compose
from vcage.scene.spec import SceneSpec
from vcage.sim.render import Renderer


def render_from_states(extras: dict[str, Any], states: np.ndarray) -> dict[str, np.ndarray]:
    """The frames of each camera (by its dataset feature key) for ``states``, rendered as ``vcage
    generate`` rendered them. DatasetError where the extras lack the scene or the configuration, or
    the states do not fit the composed scene."""
    try:
        cfg = GenerateConfig.from_dict(extras["config"])
        world = compose(SceneSpec.from_dict(extras["scene"]), cfg.sim).make_world(cfg.sim)
        if states.ndim != 2 or states.shape[1] != world.get_state().shape[0]:
            raise DatasetError(f"its states have shape {states.shape}; the composed scene's state has "
                               f"{world.get_state().shape[0]} values")
        with Renderer(world, *cfg.render.size, cfg.render.mesh_detail) as renderer:
            frames = renderer.rgb_states(states, cfg.render.cameras)
    except (KeyError, TypeError, ValueError, VcageError) as exc:
        if isinstance(exc, DatasetError):
            raise
        raise DatasetError(f"cannot render it again from its extras: {exc}") from exc
    return {camera_key(c): frames[c] for c in cfg.render.cameras}
