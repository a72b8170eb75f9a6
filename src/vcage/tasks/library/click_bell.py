"""Ring the bell by pressing its button."""

from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import PressTask


@TASKS.register("click_bell")
class ClickBell(PressTask):
    instructions = ("ring the bell", "press the button on the bell", "click the bell")
    items = (Item("bell", "bell", (0.55, 0.0)),)
    obj, point = "bell", "button"
