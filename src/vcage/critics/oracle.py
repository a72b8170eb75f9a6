"""The oracle: a subtask's ground-truth predicates evaluated on simulator state.

It is the one critic that reads the simulator, by design: every episode is audited by it, so the
label noise of the other critics can be measured. ``pressed`` is an event, not a state (a button
springs back), so it is latched while the subtask runs; every other predicate must hold on the
final state for ``hold_steps`` consecutive control steps (the caller steps the world).
"""

from __future__ import annotations

from collections.abc import Callable

from vcage.planning.schema import Predicate, Subtask
from vcage.sim.world import World
from vcage.tasks import predicates as P
from vcage.tasks.base import Latch

STATE_PREDICATES: dict[str, Callable[..., bool]] = {
    "on": lambda w, a, b: P.on(w, a, b),
    "inside": lambda w, a, b: P.inside(w, a, b),
    "stacked": lambda w, *objs: P.stacked(w, list(objs)),
    "near": lambda w, a, b: P.near(w, a, b),
    "left_of": lambda w, a, b: P.left_of(w, a, b),
    "right_of": lambda w, a, b: P.right_of(w, a, b),
    "on_table": lambda w, a: P.on_table(w, a, tol=0.02),
    "upright": lambda w, a: P.upright(w, a),
    "lifted": lambda w, a: P.lifted(w, a),
    "released": lambda w, a: not P.grasped(w, a),
}
EVENT_PREDICATES = ("pressed",)
PRESS_STEPS = 2  # a press counts once held this many consecutive control steps


class Oracle:
    """Watches one subtask at a time: :meth:`begin`, :meth:`on_step` per control step, :meth:`check`."""

    def __init__(self) -> None:
        self.latches: dict[str, Latch] = {}

    def begin(self, subtask: Subtask) -> None:
        self.latches = {p.args[0]: Latch(PRESS_STEPS) for p in subtask.predicates
                        if p.name in EVENT_PREDICATES}

    def on_step(self, world: World) -> None:
        for obj, latch in self.latches.items():
            latch.update(P.pressed(world, obj))

    def check(self, world: World, subtask: Subtask) -> dict[str, bool]:
        """Each predicate's value now (events: whether they happened during the subtask)."""
        return {str(p): self._value(world, p) for p in subtask.predicates}

    def _value(self, world: World, pred: Predicate) -> bool:
        if pred.name in EVENT_PREDICATES:
            latch = self.latches.get(pred.args[0])
            return bool(latch and latch.value)
        return bool(STATE_PREDICATES[pred.name](world, *pred.args))
