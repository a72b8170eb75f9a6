"""Put the empty cup on the coaster."""

from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import PlaceTask


@TASKS.register("place_empty_cup")
class PlaceEmptyCup(PlaceTask):
    instructions = ("put the empty cup on the coaster", "place the {obj_color} cup onto the coaster")
    items = (Item("cup", "cup", (0.5, -0.15)), Item("coaster", "coaster", (0.55, 0.12)))
    obj, target, need_upright = "cup", "coaster", True
