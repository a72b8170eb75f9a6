"""Reusable task shapes: move one object onto/into another, and press a functional point.

Concrete tasks subclass these and only declare their objects, words and instructions.
"""

from __future__ import annotations

from typing import Any, ClassVar

from vcage.sim.world import World
from vcage.skills.primitives import Skills
from vcage.tasks import predicates as P
from vcage.tasks.base import AtomicTask, Latch


class PlaceTask(AtomicTask):
    """Pick ``obj`` and put it on (or in) ``target``'s placement annotation."""

    obj: ClassVar[str]
    target: ClassVar[str]
    placement: ClassVar[str | None] = None
    relation: ClassVar[str] = "on"  # "on" | "inside"
    need_upright: ClassVar[bool] = False

    def words(self) -> dict[str, str]:
        assert self.spec is not None
        return {"obj": self.spec.object(self.obj).type.replace("_", " "),
                "target": self.spec.object(self.target).type.replace("_", " "),
                "obj_color": self.color_of(self.obj), "target_color": self.color_of(self.target)}

    def expert(self, skills: Skills) -> None:
        skills.do("pick_and_place", obj=self.obj, target=self.target, placement=self.placement)
        skills.do("retreat")

    def evaluate(self, world: World) -> dict[str, Any]:
        check = P.inside if self.relation == "inside" else P.on
        placed = check(world, self.obj, self.target, self.placement)
        released = not P.grasped(world, self.obj)
        upright = P.upright(world, self.obj) if self.need_upright else True
        return {"success": placed and released and upright, self.relation: placed,
                "released": released, "upright": upright}


class PressTask(AtomicTask):
    """Press ``obj``'s functional point ``point``; success is latched once it was held pressed."""

    obj: ClassVar[str]
    point: ClassVar[str | None] = None
    press_steps: ClassVar[int] = 2

    def setup(self, world: World) -> None:
        self.latch = Latch(self.press_steps)
        self.start = world.object_pos(self.obj)

    def on_step(self, world: World) -> None:
        self.latch.update(P.pressed(world, self.obj, self.point))

    def expert(self, skills: Skills) -> None:
        skills.do("press", obj=self.obj, point=self.point)
        skills.do("retreat")

    def evaluate(self, world: World) -> dict[str, Any]:
        upright = P.upright(world, self.obj)
        return {"success": self.latch.value and upright, "pressed": self.latch.value,
                "upright": upright}
