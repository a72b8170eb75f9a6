"""Nest three bowls: the middle-sized one in the largest, the smallest in the middle one."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from vcage.config import Randomization
from vcage.planning.schema import Predicate
from vcage.scene.layout import LayoutSpec
from vcage.skills.base import Skills
from vcage.tasks.base import TASKS, AtomicTask, Item, pred

NEST_RATIO = 0.86  # each bowl is this fraction of the scale of the one it goes into


@TASKS.register("stack_bowls_three")
class StackBowlsThree(AtomicTask):
    instructions = ("stack the three bowls",
                    "nest the bowls inside each other, the {bottom} one at the bottom",
                    "put the bowls one inside another")
    items = (Item("bowl_a", "bowl", (0.6, 0.0)), Item("bowl_b", "bowl", (0.45, -0.19)),
             Item("bowl_c", "bowl", (0.45, 0.19)))

    def layout_spec(self, rng: np.random.Generator, rand: Randomization, clutter: int = 0) -> LayoutSpec:
        layout = super().layout_spec(rng, rand, clutter)
        outer = next(o.scale for o in layout.objects if o.name == "bowl_a")
        factor = {"bowl_b": NEST_RATIO, "bowl_c": NEST_RATIO**2}
        objs = tuple(replace(o, scale=outer * factor[o.name]) if o.name in factor else o
                     for o in layout.objects)
        return replace(layout, objects=objs)

    def words(self) -> dict[str, str]:
        return {"bottom": self.color_of("bowl_a")}

    def expert(self, skills: Skills) -> None:
        skills.do("pick_and_place", obj="bowl_b", target="bowl_a")
        skills.do("pick_and_place", obj="bowl_c", target="bowl_b")
        skills.do("retreat")

    def success(self) -> tuple[Predicate, ...]:
        return (pred("inside", "bowl_b", "bowl_a"), pred("inside", "bowl_c", "bowl_b"),
                pred("released", "bowl_c"), pred("upright", "bowl_c"))
