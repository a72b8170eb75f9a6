"""The atomic task interface: ``build`` a scene, run an ``expert``, ``evaluate`` success.

A task instance lives for one episode, so it may remember what it sampled (colours, targets) and
what it observed (initial poses, latched presses) between ``build``, ``setup`` and ``evaluate``.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any, ClassVar

import numpy as np

from vcage.config import Randomization
from vcage.registry import Registry
from vcage.scene.layout import Relation, ReservedZone
from vcage.scene.placement import PlacementStats, place
from vcage.scene.spec import SceneSpec
from vcage.sim.world import World
from vcage.skills.primitives import Skills
from vcage.skills.reach import reach_map
from vcage.tasks.layout import Item, SceneConfig, task_layout

__all__ = ["TASKS", "AtomicTask", "Item", "Latch", "SceneConfig"]


class AtomicTask(ABC):
    """Base class of atomic tasks. Subclasses set ``name``, ``instructions`` and ``items``."""

    name: ClassVar[str]
    instructions: ClassVar[tuple[str, ...]]  # templates formatted with :meth:`words`
    items: ClassVar[tuple[Item, ...]] = ()
    relations: ClassVar[tuple[Relation, ...]] = ()  # between items, kept when randomised
    reserved: ClassVar[tuple[ReservedZone, ...]] = ()  # table regions the expert will use
    hold_steps: ClassVar[int] = 5  # success must hold this many consecutive control steps

    def __init__(self) -> None:
        self.spec: SceneSpec | None = None
        self.placement_stats: PlacementStats | None = None

    # -- scene -----------------------------------------------------------------------------
    def layout(self, rng: np.random.Generator) -> tuple[Item, ...]:
        """The nominal items of this episode (override to sample e.g. which object goes where)."""
        return self.items

    def build(self, rng: np.random.Generator, rand: Randomization,
              scene: SceneConfig | None = None) -> SceneSpec:
        """Lay out this episode's items and place them (context-aware unless ``scene`` says)."""
        scene = scene or SceneConfig()
        layout = task_layout(self.layout(rng), rng, rand, self.relations, self.reserved, scene.clutter)
        result = place(layout, rng, scene.placement, scene.config, reach_map())
        self.spec, self.placement_stats = result.scene, result.stats
        return self.spec

    def setup(self, world: World) -> None:
        """Called once the scene has settled, before the expert runs."""

    def on_step(self, world: World) -> None:
        """Called after every control step (for latched events such as a press)."""

    # -- behaviour ---------------------------------------------------------------------------
    @abstractmethod
    def expert(self, skills: Skills) -> None:
        """Scripted expert: a sequence of skill calls."""

    @abstractmethod
    def evaluate(self, world: World) -> dict[str, Any]:
        """Predicates on the current state; must contain a boolean ``"success"``."""

    # -- language ----------------------------------------------------------------------------
    def words(self) -> dict[str, str]:
        """Values substituted into the instruction templates (e.g. object colours)."""
        return {}

    def instruction(self, rng: np.random.Generator | None = None) -> str:
        idx = 0 if rng is None else int(rng.integers(len(self.instructions)))
        return self.instructions[idx].format(**self.words())

    def color_of(self, obj: str) -> str:
        assert self.spec is not None, "build() first"
        return self.spec.object(obj).color or ""


class Latch:
    """Becomes true once a condition held for ``steps`` consecutive control steps, and stays true."""

    def __init__(self, steps: int = 3) -> None:
        self.steps = steps
        self.count = 0
        self.value = False

    def update(self, condition: bool) -> bool:
        self.count = self.count + 1 if condition else 0
        self.value = self.value or self.count >= self.steps
        return self.value


TASKS: Registry[type[AtomicTask]] = Registry("task")
