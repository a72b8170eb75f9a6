"""Press the button on top of the alarm clock."""

from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import PressTask


@TASKS.register("click_alarmclock")
class ClickAlarmClock(PressTask):
    instructions = ("turn off the alarm clock", "press the button on top of the alarm clock")
    items = (Item("clock", "alarm_clock", (0.55, 0.05)),)
    obj, point = "clock", "button"
