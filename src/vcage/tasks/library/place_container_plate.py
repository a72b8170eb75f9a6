"""Put a container (a cup or a bowl) on the plate."""

from __future__ import annotations

import numpy as np

from vcage.tasks.base import TASKS, Item
from vcage.tasks.templates import PlaceTask

CONTAINERS = ("cup", "bowl")


@TASKS.register("place_container_plate")
class PlaceContainerPlate(PlaceTask):
    instructions = ("put the {obj} on the plate", "place the {obj_color} {obj} onto the {target_color} plate")
    obj, target, need_upright = "container", "plate", True

    def layout(self, rng: np.random.Generator) -> tuple[Item, ...]:
        kind = CONTAINERS[int(rng.integers(len(CONTAINERS)))]
        return (Item("container", kind, (0.45, -0.17)), Item("plate", "plate", (0.58, 0.12)))
