"""An object type's declared top relief (``ObjectType.top_relief``, which the image critic reads to
tell a domed top from a flat underside) is held to the model it builds, rendered and settled."""

from __future__ import annotations

import numpy as np
import pytest

from vcage.assets.catalog import CATALOG
from vcage.critics.image.measure import _relief
from vcage.scene.compose import compose
from vcage.scene.spec import ObjectSpec as O
from vcage.scene.spec import SceneSpec
from vcage.sim.render import Renderer
from vcage.tasks.verifier import render_views


@pytest.mark.parametrize("name", CATALOG.names_where(lambda t: t.top_relief > 0))
def test_a_declared_top_relief_is_what_the_top_view_shows_of_the_type_standing(name: str) -> None:
    """``ObjectType.top_relief`` is held to the model: rendered standing alone at scale 1 at four
    headings, its top lies at least that far from a plane, and not much further on average."""
    reliefs = []
    for x, y, yaw in ((0.5, 0.0, 0.0), (0.55, 0.15, 1.0), (0.6, -0.15, 2.2), (0.45, 0.1, 2.9)):
        world = compose(SceneSpec(objects=(O("x", name, (x, y), yaw=yaw),))).make_world()
        world.settle(0.3)
        with Renderer(world, 320, 240) as renderer:
            top = render_views(renderer)["top"]
        relief = _relief(top, top.segmentation == 0)
        assert relief is not None
        reliefs.append(relief)
    declared = CATALOG.get(name).top_relief
    assert declared <= min(reliefs) and declared >= 0.85 * float(np.mean(reliefs)), reliefs
