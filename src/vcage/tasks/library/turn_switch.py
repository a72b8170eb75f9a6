"""Flip the rocker switch."""

from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import PressTask


@TASKS.register("turn_switch")
class TurnSwitch(PressTask):
    instructions = ("turn on the switch", "flip the switch")
    items = (Item("switch", "switch", (0.55, 0.0)),)
    obj, point = "switch", "on"
