"""Press the stapler's arm down."""

from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import PressTask


@TASKS.register("press_stapler")
class PressStapler(PressTask):
    instructions = ("press the stapler", "push down on the stapler")
    items = (Item("stapler", "stapler", (0.55, 0.0)),)
    obj, point = "stapler", "press"
