"""Put the can into the basket."""

from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import PlaceTask


@TASKS.register("place_can_basket")
class PlaceCanBasket(PlaceTask):
    instructions = ("put the can in the basket", "place the {obj_color} can into the {target_color} basket")
    items = (Item("can", "can", (0.47, -0.16)), Item("basket", "basket", (0.56, 0.13)))
    obj, target, relation, need_upright = "can", "basket", "inside", True
