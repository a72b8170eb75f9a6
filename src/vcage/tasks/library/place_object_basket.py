"""Put an object into the basket."""

from __future__ import annotations

import numpy as np

from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import PlaceTask

OBJECTS = ("apple", "orange", "sponge", "soap", "toy_car", "tennis_ball")


@TASKS.register("place_object_basket")
class PlaceObjectBasket(PlaceTask):
    instructions = ("put the {obj} in the basket", "place the {obj_color} {obj} into the basket")
    obj, target, relation = "object", "basket", "inside"

    def layout(self, rng: np.random.Generator) -> tuple[Item, ...]:
        kind = OBJECTS[int(rng.integers(len(OBJECTS)))]
        return (Item("object", kind, (0.47, -0.15)), Item("basket", "basket", (0.56, 0.13)))
