"""Move the can next to the pot."""

from __future__ import annotations

from typing import Any

from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.tasks import predicates as P
from vcage.tasks.base import TASKS, AtomicTask, Item

GAP = 0.06  # free space between the pot's side and the can


@TASKS.register("move_can_pot")
class MoveCanPot(AtomicTask):
    instructions = ("move the can next to the pot", "put the {color} can beside the pot")
    items = (Item("can", "can", (0.45, -0.18)), Item("pot", "pot", (0.6, 0.1)))

    def words(self) -> dict[str, str]:
        return {"color": self.color_of("can")}

    def _target(self, world: World) -> tuple[float, float]:
        pot = world.object_pos("pot")
        radius = self._pot_radius(world)
        return float(pot[0] - radius - GAP), float(pot[1])

    def _pot_radius(self, world: World) -> float:
        from vcage.assets.catalog import CATALOG

        inst = world.object("pot")
        return CATALOG.get(inst.type_name).size[0] / 2 * inst.scale

    def expert(self, skills: Skills) -> None:
        skills.do("pick_and_place", obj="can", xy=self._target(skills.world))
        skills.do("retreat")

    def evaluate(self, world: World) -> dict[str, Any]:
        near = P.near(world, "can", "pot", self._pot_radius(world) + 0.12)
        standing = P.on_table(world, "can") and P.upright(world, "can")
        released = not P.grasped(world, "can")
        return {"success": near and standing and released, "near": near, "standing": standing,
                "released": released}
