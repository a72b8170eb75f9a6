"""Put object A to the left of object B."""

from __future__ import annotations

from typing import Any

import numpy as np

from vcage.scene.layout import Region, Relation, ReservedZone
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.tasks import predicates as P
from vcage.tasks.base import TASKS, AtomicTask, Item

CANDIDATES = ("apple", "can", "block", "sponge", "dice", "tape")
SIDE_OFFSET = 0.14  # how far beside B the object is put


class PlaceA2B(AtomicTask):
    """Shared by the left and right variants; ``side`` is +1 for left (+y), -1 for right."""

    side = 1
    instructions = ("put the {a} to the {side} of the {b}", "place the {a} on the {side} side of the {b}")

    def layout(self, rng: np.random.Generator) -> tuple[Item, ...]:
        a, b = rng.choice(len(CANDIDATES), size=2, replace=False)
        # A starts on the opposite side, so the expert really has to carry it across.
        return (Item("a", CANDIDATES[a], (0.45, -0.17 * self.side)),
                Item("b", CANDIDATES[b], (0.58, 0.0)))

    def words(self) -> dict[str, str]:
        assert self.spec is not None
        return {"a": self.spec.object("a").type, "b": self.spec.object("b").type,
                "side": "left" if self.side > 0 else "right"}

    def expert(self, skills: Skills) -> None:
        b = skills.world.object_pos("b")
        skills.do("pick_and_place", obj="a", xy=(float(b[0]), float(b[1] + self.side * SIDE_OFFSET)))
        skills.do("retreat")

    def evaluate(self, world: World) -> dict[str, Any]:
        rel = P.left_of if self.side > 0 else P.right_of
        beside = rel(world, "a", "b") and P.near(world, "a", "b", 0.25)
        down = P.on_table(world, "a", tol=0.02) and not P.grasped(world, "a")
        return {"success": beside and down, "beside": beside, "released_on_table": down}


def target_zone(side: int) -> ReservedZone:
    """Where A will be put: beside B's nominal position, widened by B's jitter."""
    return ReservedZone("target", Region((0.58, side * SIDE_OFFSET), (0.06, 0.06)))


@TASKS.register("place_a2b_left")
class PlaceA2BLeft(PlaceA2B):
    side = 1
    relations = (Relation("right_of", "a", "b", 0.1),)  # A starts on the other side
    reserved = (target_zone(1),)
