"""Stack one bowl inside another."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from vcage.assets.objects.containers import NEST_RATIO
from vcage.config import Randomization
from vcage.scene.layout import LayoutSpec
from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import PlaceTask


@TASKS.register("stack_bowls_two")
class StackBowlsTwo(PlaceTask):
    instructions = ("stack the {obj_color} bowl in the {target_color} bowl",
                    "put one bowl inside the other")
    items = (Item("bowl_a", "bowl", (0.47, -0.16)), Item("bowl_b", "bowl", (0.57, 0.13)))
    obj, target, relation, need_upright = "bowl_a", "bowl_b", "inside", True

    def layout_spec(self, rng: np.random.Generator, rand: Randomization, clutter: int = 0) -> LayoutSpec:
        layout = super().layout_spec(rng, rand, clutter)
        inner, outer = (next(o for o in layout.objects if o.name == n) for n in ("bowl_a", "bowl_b"))
        if inner.scale > outer.scale * NEST_RATIO and rand.enabled:
            # Bowls only nest when the one put inside is smaller; keep the randomised sizes
            # otherwise, shrinking just the inner one (before placement, so its footprint fits).
            objs = tuple(replace(o, scale=outer.scale * NEST_RATIO) if o is inner else o
                         for o in layout.objects)
            layout = replace(layout, objects=objs)
        return layout
