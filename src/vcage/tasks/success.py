"""How success is decided, for atomic tasks and for every subtask of a plan alike.

Success must *hold*: the last command is kept for a moment and the check must be true on
``HOLD_STEPS`` consecutive control steps, not on one lucky frame. Events that do not last (a
button springs back) are *latched* once they held for ``PRESS_STEPS`` consecutive steps.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from vcage.skills.base import Skills

HOLD_STEPS = 5  # consecutive control steps a success check must hold
PRESS_STEPS = 2  # consecutive control steps a press must last to count


class Latch:
    """Becomes true once a condition held for ``steps`` consecutive control steps, and stays true."""

    def __init__(self, steps: int = PRESS_STEPS) -> None:
        self.steps = steps
        self.count = 0
        self.value = False

    def update(self, condition: bool) -> bool:
        self.count = self.count + 1 if condition else 0
        self.value = self.value or self.count >= self.steps
        return self.value


def held(skills: Skills, check: Callable[[], dict[str, Any]],
         steps: int = HOLD_STEPS) -> tuple[dict[str, bool], dict[str, Any]]:
    """Keep the last command for ``2 * steps`` control steps, calling ``check`` after each.

    Returns, per key of ``check``'s dict, whether its value was true on the last ``steps``
    consecutive calls, and the last dict itself.
    """
    streak: dict[str, int] = {}
    values: dict[str, Any] = {}
    for _ in range(steps * 2):
        skills.player.wait(skills.world.control_dt)
        values = check()
        streak = {k: streak.get(k, 0) + 1 if v else 0 for k, v in values.items()}
    return {k: streak[k] >= steps for k in values}, values
