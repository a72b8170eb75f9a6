"""Put the computer mouse on the mouse pad."""

from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import PlaceTask


@TASKS.register("place_mouse_pad")
class PlaceMousePad(PlaceTask):
    instructions = ("put the mouse on the mouse pad", "place the {obj_color} mouse onto the pad",
                    "move the computer mouse onto its pad")
    items = (Item("mouse", "mouse", (0.48, -0.16), yaw=0.0),
             Item("pad", "mouse_pad", (0.55, 0.12)))
    obj, target = "mouse", "pad"
