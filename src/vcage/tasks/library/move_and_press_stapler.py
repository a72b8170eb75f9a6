"""Move the stapler onto the pad, then press it."""

from __future__ import annotations

from vcage.planning.schema import Predicate
from vcage.skills.base import Skills
from vcage.tasks.base import TASKS, Item, pred
from vcage.tasks.templates import PlaceTask


@TASKS.register("move_and_press_stapler")
class MoveAndPressStapler(PlaceTask):
    instructions = ("move the stapler onto the pad and press it",
                    "put the {obj_color} stapler on the pad, then staple")
    items = (Item("stapler", "stapler", (0.46, -0.15)), Item("pad", "mouse_pad", (0.57, 0.12)))
    obj, target, need_upright = "stapler", "pad", True

    def expert(self, skills: Skills) -> None:
        skills.do("pick_and_place", obj="stapler", target="pad")
        skills.do("press", obj="stapler", point="press")
        skills.do("retreat")

    def success(self) -> tuple[Predicate, ...]:
        return (*super().success(), pred("pressed", "stapler"))
