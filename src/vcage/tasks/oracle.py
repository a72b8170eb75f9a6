"""The oracle: predicates of the vocabulary evaluated on simulator state, one subtask at a time.

It is the one judge that reads the simulator, by design: every episode is audited by it, so the
label noise of the critics can be measured, and atomic tasks declare their success in the same
predicates. Events (``pressed``) are latched while the subtask runs; every state predicate must hold
on the final state for consecutive control steps (the caller holds, see :func:`.engine.held`).
"""

from __future__ import annotations

from collections.abc import Iterable

from vcage.planning.schema import Predicate
from vcage.sim.world import World
from vcage.tasks.predicates import ORACLE_CHECKS
from vcage.tasks.success import Latch
from vcage.vocabulary import PREDICATES, Kind


class Oracle:
    """Watches a set of predicates: :meth:`begin`, :meth:`on_step` per control step, :meth:`check`."""

    def __init__(self) -> None:
        self.latches: dict[Predicate, Latch] = {}

    def begin(self, predicates: Iterable[Predicate]) -> None:
        """Start watching ``predicates``: events are latched from now on."""
        self.latches = {p: Latch() for p in predicates if PREDICATES.get(p.name).kind is Kind.EVENT}

    def on_step(self, world: World) -> None:
        for pred, latch in self.latches.items():
            latch.update(ORACLE_CHECKS.get(pred.name)(world, *pred.args))

    def check(self, world: World, predicates: Iterable[Predicate]) -> dict[str, bool]:
        """Each predicate's value now (events: whether they happened since :meth:`begin`)."""
        return {str(p): self.value(world, p) for p in predicates}

    def value(self, world: World, pred: Predicate) -> bool:
        if pred in self.latches:
            return self.latches[pred].value
        if PREDICATES.get(pred.name).kind is Kind.EVENT:
            return False  # not watched since begin(): it cannot have happened
        return bool(ORACLE_CHECKS.get(pred.name)(world, *pred.args))
