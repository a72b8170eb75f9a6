"""Slide the deck of playing cards away to the side with the closed fingers."""

from __future__ import annotations

from typing import Any

import numpy as np

from vcage.scene.layout import Region, ReservedZone
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.tasks import predicates as P
from vcage.tasks.base import TASKS, AtomicTask, Item

DISTANCE = 0.14  # how far the fingers travel along the push
MIN_MOVED = 0.08  # how far the deck must end from where it was


@TASKS.register("move_playingcard_away")
class MovePlayingcardAway(AtomicTask):
    instructions = ("move the playing cards away", "slide the {color} deck of cards to the left",
                    "push the cards aside")
    items = (Item("cards", "card_deck", (0.52, -0.04)),)
    # the deck's path to the left stays free
    reserved = (ReservedZone("path", Region((0.52, 0.11), (0.07, 0.06))),)

    def words(self) -> dict[str, str]:
        return {"color": self.color_of("cards")}

    def setup(self, world: World) -> None:
        super().setup(world)
        self.start = world.object_pos("cards")[:2].copy()

    def expert(self, skills: Skills) -> None:
        skills.do("push", obj="cards", direction=(0.0, 1.0), distance=DISTANCE, height=0.006)
        skills.do("retreat")

    def evaluate(self, world: World) -> dict[str, Any]:
        moved = bool(np.linalg.norm(world.object_pos("cards")[:2] - self.start) >= MIN_MOVED)
        flat = P.on_table(world, "cards") and P.upright(world, "cards")
        released = not P.grasped(world, "cards")
        return {"success": moved and flat and released, "moved": moved, "flat": flat,
                "released": released}
