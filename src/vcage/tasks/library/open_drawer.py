"""Pull the cabinet's drawer open by its handle."""

from __future__ import annotations

from typing import Any

from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.tasks import predicates as P
from vcage.tasks.base import TASKS, AtomicTask, Item


@TASKS.register("open_drawer")
class OpenDrawer(AtomicTask):
    instructions = ("open the drawer", "pull the {color} cabinet's drawer open")
    items = (Item("cabinet", "cabinet", (0.62, 0.0)),)

    def words(self) -> dict[str, str]:
        return {"color": self.color_of("cabinet")}

    def expert(self, skills: Skills) -> None:
        skills.do("open_drawer", obj="cabinet")  # to the handle's stroke, 12 cm
        skills.do("retreat")

    def evaluate(self, world: World) -> dict[str, Any]:
        opened = P.opened(world, "cabinet")
        standing = P.upright(world, "cabinet") and P.on_table(world, "cabinet")
        released = not P.grasped(world, "cabinet")
        return {"success": opened and standing and released, "opened": opened, "standing": standing,
                "released": released}
