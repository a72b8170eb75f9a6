"""Put the phone on the phone stand."""

from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import PlaceTask


@TASKS.register("place_phone_stand")
class PlacePhoneStand(PlaceTask):
    instructions = ("put the phone on the phone stand", "place the {obj_color} phone onto its stand")
    items = (Item("phone", "phone", (0.47, -0.16)), Item("stand", "phone_stand", (0.58, 0.12)))
    obj, target = "phone", "stand"
