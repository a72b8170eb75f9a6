"""Lift the pot off the table by its handle."""

from __future__ import annotations

from typing import Any

from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.tasks import predicates as P
from vcage.tasks.base import TASKS, AtomicTask, Item


@TASKS.register("lift_pot")
class LiftPot(AtomicTask):
    instructions = ("lift the pot", "pick up the pot by its handle")
    items = (Item("pot", "pot", (0.52, 0.0)),)

    def expert(self, skills: Skills) -> None:
        skills.do("grasp", obj="pot")
        skills.do("lift", height=0.12)

    def evaluate(self, world: World) -> dict[str, Any]:
        lifted = P.lifted(world, "pot", 0.06)
        held = P.grasped(world, "pot")
        return {"success": lifted and held, "lifted": lifted, "held": held}
