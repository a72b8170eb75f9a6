"""Throw both bottles into the dustbin."""

from __future__ import annotations

from vcage.planning.schema import Predicate
from vcage.skills.base import Skills
from vcage.tasks.base import TASKS, AtomicTask, Item, pred
from vcage.tasks.library._support import local_xy

SLOT_Y = 0.045  # each bottle's place beside the bin's middle (bin frame, scale 1)


@TASKS.register("put_bottles_dustbin")
class PutBottlesDustbin(AtomicTask):
    instructions = ("put the bottles in the dustbin", "throw both bottles into the {color} bin")
    items = (Item("bottle_a", "bottle", (0.42, 0.2)), Item("bottle_b", "bottle", (0.42, -0.2)),
             Item("bin", "dustbin", (0.62, 0.0)))

    def words(self) -> dict[str, str]:
        return {"color": self.color_of("bin")}

    def expert(self, skills: Skills) -> None:
        world = skills.world
        for bottle, side in (("bottle_a", 1), ("bottle_b", -1)):
            skills.do("grasp", obj=bottle, grasp_name=None)
            skills.do("lift", height=0.18)
            skills.do("place", obj=bottle, xy=local_xy(world, "bin", (0.0, side * SLOT_Y)))
        skills.do("retreat")

    def success(self) -> tuple[Predicate, ...]:
        return (pred("inside", "bottle_a", "bin"), pred("inside", "bottle_b", "bin"),
                pred("released", "bottle_a"), pred("released", "bottle_b"))
