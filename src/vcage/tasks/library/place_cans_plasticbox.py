"""Put both cans into the plastic box."""

from __future__ import annotations

from vcage.planning.schema import Predicate
from vcage.skills.base import Skills
from vcage.tasks.base import TASKS, AtomicTask, Item, pred
from vcage.tasks.library._support import local_xy

SLOT_Y = 0.06  # each can's place beside the box's middle (box frame, scale 1)


@TASKS.register("place_cans_plasticbox")
class PlaceCansPlasticbox(AtomicTask):
    instructions = ("put the cans in the plastic box", "place both cans into the {color} plastic box")
    items = (Item("can_a", "can", (0.42, 0.2)), Item("can_b", "can", (0.42, -0.2)),
             Item("box", "plastic_box", (0.62, 0.0)))

    def words(self) -> dict[str, str]:
        return {"color": self.color_of("box")}

    def expert(self, skills: Skills) -> None:
        world = skills.world
        for can, side in (("can_a", 1), ("can_b", -1)):
            skills.do("pick_and_place", obj=can, xy=local_xy(world, "box", (0.0, side * SLOT_Y)))
        skills.do("retreat")

    def success(self) -> tuple[Predicate, ...]:
        return (pred("inside", "can_a", "box"), pred("inside", "can_b", "box"),
                pred("released", "can_a"), pred("released", "can_b"),
                pred("upright", "can_a"), pred("upright", "can_b"))
