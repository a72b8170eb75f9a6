"""Stack one bowl inside another."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from vcage.config import Randomization
from vcage.scene.spec import SceneSpec
from vcage.tasks.base import TASKS, Item, SceneConfig
from vcage.tasks.templates import PlaceTask

NEST_RATIO = 0.92  # the inner bowl is at most this fraction of the outer bowl's scale


@TASKS.register("stack_bowls_two")
class StackBowlsTwo(PlaceTask):
    instructions = ("stack the {obj_color} bowl in the {target_color} bowl",
                    "put one bowl inside the other")
    items = (Item("bowl_a", "bowl", (0.47, -0.16)), Item("bowl_b", "bowl", (0.57, 0.13)))
    obj, target, relation, need_upright = "bowl_a", "bowl_b", "inside", True

    def build(self, rng: np.random.Generator, rand: Randomization,
              scene: SceneConfig | None = None) -> SceneSpec:
        spec = super().build(rng, rand, scene)
        inner, outer = spec.object("bowl_a"), spec.object("bowl_b")
        if inner.scale > outer.scale * NEST_RATIO and rand.enabled:
            # Bowls only nest when the one put inside is smaller; keep the randomised sizes
            # otherwise, shrinking just the inner one.
            objs = tuple(replace(o, scale=outer.scale * NEST_RATIO) if o.name == "bowl_a" else o
                         for o in spec.objects)
            spec = replace(spec, objects=objs)
        self.spec = spec
        return spec
