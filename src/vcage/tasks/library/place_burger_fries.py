"""Put the burger and the fries on the tray, one at each end."""

from __future__ import annotations

import math

from vcage.planning.schema import Predicate
from vcage.skills.base import Skills
from vcage.tasks.base import TASKS, AtomicTask, Item, pred
from vcage.tasks.library._support import local_xy

END_X = 0.065  # each item's place either side of the tray's middle (tray frame, scale 1)


@TASKS.register("place_burger_fries")
class PlaceBurgerFries(AtomicTask):
    instructions = ("put the burger and the fries on the tray",
                    "serve the burger and fries on the {color} tray")
    items = (Item("burger", "burger", (0.43, -0.2)), Item("fries", "fries", (0.43, 0.2)),
             Item("tray", "tray", (0.6, 0.0), yaw=math.pi / 2))

    def words(self) -> dict[str, str]:
        return {"color": self.color_of("tray")}

    def expert(self, skills: Skills) -> None:
        world = skills.world
        for obj, end in (("burger", -1), ("fries", 1)):
            skills.do("pick_and_place", obj=obj, xy=local_xy(world, "tray", (end * END_X, 0.0)))
        skills.do("retreat")

    def success(self) -> tuple[Predicate, ...]:
        return (pred("inside", "burger", "tray"), pred("inside", "fries", "tray"),
                pred("released", "burger"), pred("released", "fries"), pred("upright", "fries"))
