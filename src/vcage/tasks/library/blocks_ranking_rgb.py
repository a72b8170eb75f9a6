"""Line up red, green and blue blocks from left to right."""

from __future__ import annotations

from typing import Any

import numpy as np

from vcage.scene.layout import Region, ReservedZone
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.tasks import predicates as P
from vcage.tasks.base import TASKS, AtomicTask, Item

ROW_X = 0.42
SLOTS_Y = (0.12, 0.0, -0.12)  # left to right as seen from the robot (+y is left)
SLOT_TOL = 0.04  # how close to its slot in the row each block must end


@TASKS.register("blocks_ranking_rgb")
class BlocksRankingRGB(AtomicTask):
    instructions = (
        "arrange the blocks in a row: red, green, blue from left to right",
        "line up the red, green and blue blocks from left to right",
        "rank the blocks by colour: red, then green, then blue",
    )

    # the target row stays free of clutter
    reserved = (ReservedZone("row", Region((ROW_X, 0.0), (0.04, max(SLOTS_Y) + 0.04))),)

    def layout(self, rng: np.random.Generator) -> tuple[Item, ...]:
        # Shuffle which colour starts where, in a back row away from the target row.
        colors = ["red", "green", "blue"]
        order = rng.permutation(3)
        starts = ((0.62, 0.15), (0.64, 0.0), (0.62, -0.15))
        return tuple(Item(f"block_{colors[i]}", "block", starts[k], colors=(colors[i],))
                     for k, i in enumerate(order))

    def expert(self, skills: Skills) -> None:
        for name, y in zip(("block_red", "block_green", "block_blue"), SLOTS_Y, strict=True):
            skills.do("pick_and_place", obj=name, xy=(ROW_X, y))
        skills.do("retreat")

    def evaluate(self, world: World) -> dict[str, Any]:
        order = (P.left_of(world, "block_red", "block_green")
                 and P.left_of(world, "block_green", "block_blue"))
        on_table = all(P.on_table(world, b) for b in ("block_red", "block_green", "block_blue"))
        in_row = all(np.linalg.norm(world.object_pos(b)[:2] - [ROW_X, y]) < SLOT_TOL
                     for b, y in zip(("block_red", "block_green", "block_blue"), SLOTS_Y, strict=True))
        return {"success": order and on_table and in_row, "order": order,
                "on_table": on_table, "in_row": in_row}
