"""Put an object on the kitchen scale."""

from __future__ import annotations

import numpy as np

from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import PlaceTask

OBJECTS = ("apple", "orange", "block", "dice", "soap", "can")


@TASKS.register("place_object_scale")
class PlaceObjectScale(PlaceTask):
    instructions = ("put the {obj} on the scale", "weigh the {obj_color} {obj} on the kitchen scale")
    obj, target = "object", "scale"

    def layout(self, rng: np.random.Generator) -> tuple[Item, ...]:
        kind = OBJECTS[int(rng.integers(len(OBJECTS)))]
        return (Item("object", kind, (0.46, -0.15)), Item("scale", "kitchen_scale", (0.57, 0.12)))
