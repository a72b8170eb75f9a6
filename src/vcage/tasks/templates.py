"""Reusable task shapes: move one object onto/into another, press a functional point, and lift
an object and hold it up.

Concrete tasks subclass these and only declare their objects, words and instructions.
"""

from __future__ import annotations

from typing import Any, ClassVar

from vcage.geometry import wrap_half_turn, yaw_of
from vcage.planning.schema import Predicate
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.tasks import predicates as P
from vcage.tasks.base import AtomicTask, pred


def heading(world: World, obj: str) -> float:
    """``obj``'s yaw in the world."""
    return yaw_of(world.object_mat(obj))


def turn_to_align(world: World, obj: str, host: str) -> float:
    """The smallest turn (within ±pi/2) that lines ``obj`` up with ``host``'s axes (mod pi)."""
    return wrap_half_turn(heading(world, host) - heading(world, obj))


class PlaceTask(AtomicTask):
    """Pick ``obj`` and put it on (or in) ``target``'s placement surface, and let go."""

    obj: ClassVar[str]
    target: ClassVar[str]
    relation: ClassVar[str] = "on"  # "on" | "inside"
    need_upright: ClassVar[bool] = False
    align: ClassVar[bool] = False  # turn ``obj`` on the way so its axes line up with ``target``'s

    def words(self) -> dict[str, str]:
        assert self.spec is not None
        return {"obj": self.spec.object(self.obj).type.replace("_", " "),
                "target": self.spec.object(self.target).type.replace("_", " "),
                "obj_color": self.color_of(self.obj), "target_color": self.color_of(self.target)}

    def expert(self, skills: Skills) -> None:
        if self.align:  # a long object into a tight rectangular container
            skills.do("grasp", obj=self.obj)
            skills.do("lift")
            skills.do("turn_and_place", obj=self.obj, target=self.target,
                      turn=turn_to_align(skills.world, self.obj, self.target))
        else:
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


class LiftTask(AtomicTask):
    """Grasp ``obj`` and hold it up, level: lifted and upright (predicates) while still held."""

    obj: ClassVar[str]
    height: ClassVar[float] = 0.12
    grasp_name: ClassVar[str | None] = None

    def words(self) -> dict[str, str]:
        return {"obj_color": self.color_of(self.obj)}

    def expert(self, skills: Skills) -> None:
        skills.do("grasp", obj=self.obj, grasp_name=self.grasp_name)
        skills.do("lift", height=self.height)

    def success(self) -> tuple[Predicate, ...]:
        return pred("lifted", self.obj), pred("upright", self.obj)

    def evaluate(self, world: World) -> dict[str, Any]:
        values = super().evaluate(world)
        held = P.grasped(world, self.obj)
        return {**values, "success": values["success"] and held, "held": held}
