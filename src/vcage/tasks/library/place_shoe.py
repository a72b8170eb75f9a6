"""Put the shoe on the mat."""

from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import PlaceTask


@TASKS.register("place_shoe")
class PlaceShoe(PlaceTask):
    instructions = ("put the shoe on the mat", "place the {obj_color} shoe onto the {target_color} mat")
    items = (Item("shoe", "shoe", (0.46, -0.16)), Item("mat", "mouse_pad", (0.57, 0.12)))
    obj, target, need_upright = "shoe", "mat", True
