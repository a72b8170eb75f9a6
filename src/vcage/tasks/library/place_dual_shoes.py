"""Put both shoes into the shoe box, side by side, one after the other."""

from __future__ import annotations

import numpy as np

from vcage.planning.schema import Predicate
from vcage.skills.base import Skills
from vcage.tasks.base import TASKS, AtomicTask, Item, pred
from vcage.tasks.library._support import local_xy, turn_to_align

SLOT_Y = 0.058  # each shoe's place beside the box's middle (box frame, scale 1)


@TASKS.register("place_dual_shoes")
class PlaceDualShoes(AtomicTask):
    instructions = ("put both shoes in the shoe box", "place the pair of {color} shoes into the box",
                    "pack the two shoes into the shoe box")
    items = (Item("shoe_left", "shoe", (0.42, 0.2)), Item("shoe_right", "shoe", (0.42, -0.2)),
             Item("box", "shoe_box", (0.62, 0.0)))

    def words(self) -> dict[str, str]:
        return {"color": self.color_of("shoe_left")}

    def layout(self, rng: np.random.Generator) -> tuple[Item, ...]:
        # one pair: both shoes take the same colour
        color = str(rng.choice(["white", "black", "red", "blue"]))
        return tuple(Item(i.name, i.type, i.xy, i.yaw, colors=(color,)) if i.type == "shoe" else i
                     for i in self.items)

    def expert(self, skills: Skills) -> None:
        world = skills.world
        for shoe, side in (("shoe_left", 1), ("shoe_right", -1)):
            skills.do("grasp", obj=shoe)
            skills.do("lift")
            skills.do("turn_and_place", obj=shoe, turn=turn_to_align(world, shoe, "box"),
                      xy=local_xy(world, "box", (0.0, side * SLOT_Y)))
        skills.do("retreat")

    def success(self) -> tuple[Predicate, ...]:
        return (pred("inside", "shoe_left", "box"), pred("inside", "shoe_right", "box"),
                pred("released", "shoe_left"), pred("released", "shoe_right"))
