"""Pick up the bottle and hold it up, head up."""

from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import LiftTask


@TASKS.register("adjust_bottle")
class AdjustBottle(LiftTask):
    instructions = ("pick up the bottle and hold it head up", "lift the {obj_color} bottle upright")
    items = (Item("bottle", "bottle", (0.5, -0.08)),)
    obj, grasp_name = "bottle", None
