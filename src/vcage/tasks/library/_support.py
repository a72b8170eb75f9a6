"""Helpers shared by task modules (not a task: the library skips modules starting with ``_``)."""

from __future__ import annotations

import numpy as np

from vcage.assets.catalog import CATALOG
from vcage.sim.world import World
from vcage.tasks.templates import heading, turn_to_align

__all__ = ["heading", "local_xy", "top_of", "turn_to_align"]


def local_xy(world: World, host: str, local: tuple[float, float]) -> tuple[float, float]:
    """The table position of point ``local`` (object frame, scale 1) of object ``host``."""
    inst = world.object(host)
    p = world.object_pos(host) + world.object_mat(host) @ (np.array([*local, 0.0]) * inst.scale)
    return float(p[0]), float(p[1])


def top_of(world: World, obj: str) -> float:
    """Height of ``obj``'s top (its catalog height, scaled, above its origin)."""
    inst = world.object(obj)
    return float(world.object_pos(obj)[2] + CATALOG.get(inst.type_name).size[2] * inst.scale)


