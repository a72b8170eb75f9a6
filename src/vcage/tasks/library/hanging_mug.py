"""Hang the mug on the rack's peg by its handle."""

from __future__ import annotations

from typing import Any

from vcage.scene.layout import Region, ReservedZone
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.tasks import predicates as P
from vcage.tasks.base import TASKS, AtomicTask, Item


@TASKS.register("hanging_mug")
class HangingMug(AtomicTask):
    instructions = ("hang the mug on the rack", "hang the {color} mug on the mug rack by its handle")
    items = (Item("mug", "mug", (0.45, -0.12)), Item("rack", "mug_rack", (0.63, 0.08)))
    # where the mug comes down beside the peg's end
    reserved = (ReservedZone("approach", Region((0.6, -0.06), (0.06, 0.05))),)

    def words(self) -> dict[str, str]:
        return {"color": self.color_of("mug")}

    def expert(self, skills: Skills) -> None:
        skills.do("hang", obj="mug", target="rack")
        skills.do("retreat")

    def evaluate(self, world: World) -> dict[str, Any]:
        hanging = P.hanging(world, "mug", "rack")
        released = not P.grasped(world, "mug")
        rack_up = P.upright(world, "rack")
        return {"success": hanging and released and rack_up, "hanging": hanging, "released": released,
                "rack_upright": rack_up}
