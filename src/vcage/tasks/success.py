"""How success is decided, for atomic tasks and for every subtask of a plan alike.

Success must *hold*: the last command is kept for a moment and the check must be true on
``HOLD_STEPS`` consecutive control steps, not on one lucky frame (the episode engine holds:
:func:`vcage.tasks.engine.held`). Events that do not last (a button springs back) are *latched*
once they held for ``PRESS_STEPS`` consecutive steps.
"""

from __future__ import annotations

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
