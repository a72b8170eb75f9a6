"""Pick up the bottle and shake it."""

from __future__ import annotations

from typing import Any

from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.tasks import predicates as P
from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import LiftTask

AMPLITUDE = 0.05  # the hand moves this far either way
MIN_SWING = 0.06  # the held bottle's lateral travel that counts as shaken


@TASKS.register("shake_bottle")
class ShakeBottle(LiftTask):
    instructions = ("shake the bottle", "pick up the {obj_color} bottle and shake it")
    items = (Item("bottle", "bottle", (0.5, -0.05)),)
    obj, height = "bottle", 0.15

    def setup(self, world: World) -> None:
        super().setup(world)
        self.swing: list[float] = []  # lateral positions of the bottle while held up

    def on_step(self, world: World) -> None:
        super().on_step(world)
        if P.lifted(world, self.obj) and P.grasped(world, self.obj):
            self.swing.append(float(world.object_pos(self.obj)[1]))

    def expert(self, skills: Skills) -> None:
        super().expert(skills)
        skills.do("shake", amplitude=AMPLITUDE, cycles=3)

    def evaluate(self, world: World) -> dict[str, Any]:
        values = super().evaluate(world)
        shaken = bool(self.swing) and max(self.swing) - min(self.swing) >= MIN_SWING
        return {**values, "success": values["success"] and shaken, "shaken": shaken}
