"""Put an object on the display stand."""

from __future__ import annotations

import numpy as np

from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import PlaceTask

OBJECTS = ("apple", "block", "dice", "orange")


@TASKS.register("place_object_stand")
class PlaceObjectStand(PlaceTask):
    instructions = ("put the {obj} on the stand", "place the {obj_color} {obj} on the display stand")
    obj, target = "object", "stand"

    def layout(self, rng: np.random.Generator) -> tuple[Item, ...]:
        kind = OBJECTS[int(rng.integers(len(OBJECTS)))]
        return (Item("object", kind, (0.46, -0.15)), Item("stand", "object_stand", (0.57, 0.12)))
