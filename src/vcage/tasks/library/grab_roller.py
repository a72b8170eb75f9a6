"""Grab the rolling pin by its barrel and lift it, level."""

import math

from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import LiftTask


@TASKS.register("grab_roller")
class GrabRoller(LiftTask):
    instructions = ("grab the roller and lift it", "pick up the {obj_color} rolling pin")
    items = (Item("roller", "roller", (0.52, 0.0), yaw=math.pi / 2),)
    obj = "roller"
