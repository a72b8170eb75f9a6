"""Pick up the hammer and strike the block with its head."""

from __future__ import annotations

from typing import Any

import numpy as np

from vcage.assets.catalog import CATALOG
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.tasks import predicates as P
from vcage.tasks.base import TASKS, AtomicTask, Item
from vcage.tasks.library._support import top_of

ABOVE = 0.06  # the head is brought this far above the block before coming down
PRESS = 0.015  # and comes down this far past the block's top face (the grip gives way)
HEAD_TOL = 0.035  # the head must land within this of the block's centre (xy)


def head_pos(world: World, obj: str = "hammer") -> np.ndarray:
    """World position of the hammer head's striking face."""
    inst = world.object(obj)
    fp = CATALOG.get(inst.type_name).functional_point("head")
    return world.object_pos(obj) + world.object_mat(obj) @ (np.asarray(fp.pos) * inst.scale)


@TASKS.register("beat_block_hammer")
class BeatBlockHammer(AtomicTask):
    instructions = ("beat the block with the hammer", "hit the {block} block with the {hammer} hammer")
    items = (Item("hammer", "hammer", (0.45, -0.15)), Item("block", "block", (0.58, 0.1)))

    def words(self) -> dict[str, str]:
        return {"block": self.color_of("block"), "hammer": self.color_of("hammer")}

    def expert(self, skills: Skills) -> None:
        world = skills.world
        skills.do("grasp", obj="hammer")
        skills.do("lift", height=0.1)
        offset = head_pos(world) - skills.tcp()[0]  # the head relative to the hand, as held
        strike = world.object_pos("block").copy()
        strike[2] = top_of(world, "block") - PRESS
        skills.do("move_to", pos=strike - offset + [0.0, 0.0, ABOVE])
        skills.do("move_line", pos=strike - offset, speed=0.15, hold=0.3)

    def evaluate(self, world: World) -> dict[str, Any]:
        struck = P.contact_between(world, "hammer", "block")
        on_target = bool(np.linalg.norm(head_pos(world)[:2] - world.object_pos("block")[:2]) <= HEAD_TOL)
        held = P.grasped(world, "hammer")
        block_down = P.on_table(world, "block") and P.upright(world, "block")
        return {"success": struck and on_target and held and block_down, "struck": struck,
                "on_target": on_target, "held": held, "block_down": block_down}
