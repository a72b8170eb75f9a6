"""Open the cabinet's drawer, put an object in it, and shut the drawer again."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from vcage.assets.objects.tools import CAB_HALF, CAB_X0
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.skills.drawers import opening
from vcage.tasks import predicates as P
from vcage.tasks.base import TASKS, AtomicTask, Item
from vcage.tasks.library._support import local_xy, turn_to_align

OBJECTS = ("sponge", "soap")  # low enough to pass under the cabinet's top
OPENING = 0.13


@TASKS.register("put_object_cabinet")
class PutObjectCabinet(AtomicTask):
    instructions = ("put the {obj} in the drawer and close it",
                    "open the drawer, put the {color} {obj} inside, and shut the drawer")

    def layout(self, rng: np.random.Generator) -> tuple[Item, ...]:
        kind = OBJECTS[int(rng.integers(len(OBJECTS)))]
        return (Item("object", kind, (0.45, 0.2)), Item("cabinet", "cabinet", (0.64, -0.05)))

    def words(self) -> dict[str, str]:
        assert self.spec is not None
        return {"obj": self.spec.object("object").type, "color": self.color_of("object")}

    def expert(self, skills: Skills) -> None:
        world = skills.world
        skills.do("open_drawer", obj="cabinet", distance=OPENING)
        out = opening(world, "cabinet")  # the drawer has come out by this much
        # the middle of the drawer's uncovered part: between its front and the cabinet's top
        front = CAB_X0 - CAB_HALF[0] - 0.004 - out
        x = (front + CAB_X0 - CAB_HALF[0]) / 2
        skills.do("grasp", obj="object")
        skills.do("lift")
        turn = turn_to_align(world, "object", "cabinet") + math.pi / 2  # long side across the drawer
        skills.do("turn_and_place", obj="object", turn=math.remainder(2 * turn, 2 * math.pi) / 2,
                  xy=local_xy(world, "cabinet", (x, 0.0)))
        skills.do("close_drawer", obj="cabinet")
        skills.do("retreat")

    def evaluate(self, world: World) -> dict[str, Any]:
        inside = P.inside(world, "object", "cabinet")
        shut = P.closed(world, "cabinet")
        released = not P.grasped(world, "object")
        return {"success": inside and shut and released, "inside": inside, "shut": shut,
                "released": released}
