"""Line up three blocks from the largest (left) to the smallest (right)."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from vcage.config import Randomization
from vcage.scene.layout import LayoutSpec, Region, ReservedZone
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.tasks import predicates as P
from vcage.tasks.base import TASKS, AtomicTask, Item
from vcage.tasks.library.blocks_ranking_rgb import ROW_X, SLOT_TOL, SLOTS_Y

SIZES = {"block_large": 1.25, "block_medium": 1.0, "block_small": 0.78}  # factors on the block's scale
ORDER = tuple(SIZES)  # left to right


@TASKS.register("blocks_ranking_size")
class BlocksRankingSize(AtomicTask):
    instructions = (
        "arrange the blocks by size from largest to smallest, left to right",
        "line up the blocks: the big one on the left, the small one on the right",
        "rank the blocks by size, largest first",
    )
    reserved = (ReservedZone("row", Region((ROW_X, 0.0), (0.045, max(SLOTS_Y) + 0.045))),)

    def layout(self, rng: np.random.Generator) -> tuple[Item, ...]:
        order = rng.permutation(3)
        starts = ((0.62, 0.15), (0.64, 0.0), (0.62, -0.15))
        return tuple(Item(ORDER[i], "block", starts[k]) for k, i in enumerate(order))

    def layout_spec(self, rng: np.random.Generator, rand: Randomization, clutter: int = 0) -> LayoutSpec:
        layout = super().layout_spec(rng, rand, clutter)
        objs = tuple(replace(o, scale=o.scale * SIZES[o.name]) if o.name in SIZES else o
                     for o in layout.objects)
        return replace(layout, objects=objs)

    def expert(self, skills: Skills) -> None:
        for name, y in zip(ORDER, SLOTS_Y, strict=True):
            skills.do("pick_and_place", obj=name, xy=(ROW_X, y))
        skills.do("retreat")

    def evaluate(self, world: World) -> dict[str, Any]:
        order = P.left_of(world, ORDER[0], ORDER[1]) and P.left_of(world, ORDER[1], ORDER[2])
        on_table = all(P.on_table(world, b) for b in ORDER)
        released = not any(P.grasped(world, b) for b in ORDER)
        in_row = all(np.linalg.norm(world.object_pos(b)[:2] - [ROW_X, y]) < SLOT_TOL
                     for b, y in zip(ORDER, SLOTS_Y, strict=True))
        return {"success": order and on_table and in_row and released, "order": order,
                "on_table": on_table, "in_row": in_row, "released": released}
