"""Put the bread into the basket."""

from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import PlaceTask


@TASKS.register("place_bread_basket")
class PlaceBreadBasket(PlaceTask):
    instructions = ("put the bread in the basket", "place the loaf of bread into the {target_color} basket")
    items = (Item("bread", "bread", (0.48, -0.16)), Item("basket", "basket", (0.55, 0.14)))
    obj, target, relation, align = "bread", "basket", "inside", True
