"""Reusable task shapes: move one object onto/into another, and press a functional point.

Concrete tasks subclass these and only declare their objects, words and instructions.
"""

from __future__ import annotations

from typing import ClassVar

from vcage.planning.schema import Predicate
from vcage.skills.base import Skills
from vcage.tasks.base import AtomicTask, pred


class PlaceTask(AtomicTask):
    """Pick ``obj`` and put it on (or in) ``target``'s placement surface, and let go."""

    obj: ClassVar[str]
    target: ClassVar[str]
    relation: ClassVar[str] = "on"  # "on" | "inside"
    need_upright: ClassVar[bool] = False

    def words(self) -> dict[str, str]:
        assert self.spec is not None
        return {"obj": self.spec.object(self.obj).type.replace("_", " "),
                "target": self.spec.object(self.target).type.replace("_", " "),
                "obj_color": self.color_of(self.obj), "target_color": self.color_of(self.target)}

    def expert(self, skills: Skills) -> None:
        skills.do("pick_and_place", obj=self.obj, target=self.target)
        skills.do("retreat")

    def success(self) -> tuple[Predicate, ...]:
        upright = (pred("upright", self.obj),) if self.need_upright else ()
        return (pred(self.relation, self.obj, self.target), pred("released", self.obj), *upright)


class PressTask(AtomicTask):
    """Press ``obj``'s (first) functional point; the press is latched once it was held."""

    obj: ClassVar[str]
    point: ClassVar[str | None] = None  # the skill's target point; ``pressed`` watches the first

    def expert(self, skills: Skills) -> None:
        skills.do("press", obj=self.obj, point=self.point)
        skills.do("retreat")

    def success(self) -> tuple[Predicate, ...]:
        return (pred("pressed", self.obj), pred("upright", self.obj))
