"""Stamp the seal onto the mat."""

from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import PlaceTask


@TASKS.register("stamp_seal")
class StampSeal(PlaceTask):
    instructions = ("stamp the seal on the {target_color} mat", "put the seal down on the mat")
    items = (Item("seal", "seal", (0.47, -0.15)), Item("mat", "stamp_mat", (0.57, 0.12)))
    obj, target, need_upright = "seal", "mat", True
