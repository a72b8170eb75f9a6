"""The atomic task interface: a scene ``layout``, an ``expert``, and success in the vocabulary.

A task instance lives for one episode, so it may remember what it sampled (colours, targets) and
what it observed between :meth:`AtomicTask.layout_spec`, :meth:`AtomicTask.setup` and
:meth:`AtomicTask.evaluate`. Success is declared as predicates of :mod:`vcage.vocabulary` in
:meth:`AtomicTask.success` and judged by the same oracle that audits every subtask of a plan;
a task whose success needs other measures (a distance, a row) overrides :meth:`evaluate`.

A new task is one module in :mod:`vcage.tasks.library` that registers its class in ``TASKS``.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any, ClassVar

import numpy as np

from vcage.config import Randomization
from vcage.planning.schema import Predicate
from vcage.registry import Registry
from vcage.scene.layout import LayoutSpec, Relation, ReservedZone
from vcage.scene.spec import SceneSpec
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.tasks.items import Item, task_layout
from vcage.tasks.oracle import Oracle
from vcage.tasks.success import HOLD_STEPS

__all__ = ["TASKS", "AtomicTask", "Item", "pred"]


def pred(name: str, *args: str) -> Predicate:
    """A predicate of the vocabulary, e.g. ``pred("on", "mouse", "pad")``."""
    return Predicate(name=name, args=args)


class AtomicTask(ABC):
    """Base class of atomic tasks. Subclasses set ``name``, ``instructions`` and ``items``."""

    name: ClassVar[str]
    instructions: ClassVar[tuple[str, ...]]  # templates formatted with :meth:`words`
    items: ClassVar[tuple[Item, ...]] = ()
    relations: ClassVar[tuple[Relation, ...]] = ()  # between items, kept when randomised
    reserved: ClassVar[tuple[ReservedZone, ...]] = ()  # table regions the expert will use
    hold_steps: ClassVar[int] = HOLD_STEPS  # success must hold this many consecutive control steps

    def __init__(self) -> None:
        self.spec: SceneSpec | None = None
        self.oracle = Oracle()

    # -- scene -----------------------------------------------------------------------------
    def layout(self, rng: np.random.Generator) -> tuple[Item, ...]:
        """The nominal items of this episode (override to sample e.g. which object goes where)."""
        return self.items

    def layout_spec(self, rng: np.random.Generator, rand: Randomization, clutter: int = 0) -> LayoutSpec:
        """This episode's layout: its items randomised by ``rand``, with ``clutter`` distractors."""
        return task_layout(self.layout(rng), rng, rand, self.relations, self.reserved, clutter)

    def setup(self, world: World) -> None:
        """Called once the scene has settled, before the expert runs: the oracle starts watching
        (events such as a press are latched from here on). Overrides call ``super().setup``."""
        self.oracle.begin(self.success())

    def on_step(self, world: World) -> None:
        """Called after every control step."""
        self.oracle.on_step(world)

    # -- behaviour ---------------------------------------------------------------------------
    @abstractmethod
    def expert(self, skills: Skills) -> None:
        """Scripted expert: a sequence of skill calls."""

    def success(self) -> tuple[Predicate, ...]:
        """The predicates that must all hold for the task to succeed."""
        return ()

    def evaluate(self, world: World) -> dict[str, Any]:
        """Each success predicate's value now, and ``"success"``: whether all hold."""
        preds = self.success()
        if not preds:
            raise NotImplementedError(f"{type(self).__name__} declares no success predicates; "
                                      "override success() or evaluate()")
        values = self.oracle.check(world, preds)
        return {"success": all(values.values()), **values}

    # -- language ----------------------------------------------------------------------------
    def words(self) -> dict[str, str]:
        """Values substituted into the instruction templates (e.g. object colours)."""
        return {}

    def instruction(self, rng: np.random.Generator | None = None) -> str:
        idx = 0 if rng is None else int(rng.integers(len(self.instructions)))
        return self.instructions[idx].format(**self.words())

    def color_of(self, obj: str) -> str:
        assert self.spec is not None, "instantiate the scene first"
        return self.spec.object(obj).color or ""


TASKS: Registry[type[AtomicTask]] = Registry("task")
