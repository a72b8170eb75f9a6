"""Move the stapler onto the pad."""

from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import PlaceTask


@TASKS.register("move_stapler_pad")
class MoveStaplerPad(PlaceTask):
    instructions = ("move the stapler onto the pad", "put the {obj_color} stapler on the {target_color} pad")
    items = (Item("stapler", "stapler", (0.46, -0.15)), Item("pad", "mouse_pad", (0.57, 0.12)))
    obj, target, need_upright = "stapler", "pad", True
