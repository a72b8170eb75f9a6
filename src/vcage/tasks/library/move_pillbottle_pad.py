"""Move the pill bottle onto the pad."""

from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import PlaceTask


@TASKS.register("move_pillbottle_pad")
class MovePillbottlePad(PlaceTask):
    instructions = ("move the pill bottle onto the pad",
                    "put the {obj_color} pill bottle on the {target_color} pad")
    items = (Item("pillbottle", "pill_bottle", (0.47, -0.15)), Item("pad", "mouse_pad", (0.57, 0.12)))
    obj, target, need_upright = "pillbottle", "pad", True
