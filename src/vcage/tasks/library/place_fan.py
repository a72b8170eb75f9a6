"""Put the fan on the mat, facing the robot."""

from __future__ import annotations

import math
from typing import Any

from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.tasks import predicates as P
from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import PlaceTask


@TASKS.register("place_fan")
class PlaceFan(PlaceTask):
    instructions = ("put the fan on the mat, facing me",
                    "place the {obj_color} fan onto the mat so it faces the robot")
    items = (Item("fan", "fan", (0.46, -0.16), yaw=math.pi / 2), Item("mat", "mouse_pad", (0.57, 0.13)))
    obj, target, need_upright = "fan", "mat", True

    def expert(self, skills: Skills) -> None:
        skills.do("turn_to_face", obj="fan", target="mat")
        skills.do("retreat")

    def evaluate(self, world: World) -> dict[str, Any]:
        values = super().evaluate(world)
        facing = P.facing(world, "fan")
        return {**values, "success": values["success"] and facing, "facing": facing}
