"""Helpers shared by task modules (not a task: the library skips modules starting with ``_``)."""

from __future__ import annotations

import math

import numpy as np

from vcage.assets.catalog import CATALOG
from vcage.geometry import wrap_angle
from vcage.scene.spec import ROBOT_MOUNT
from vcage.sim.world import World
from vcage.tasks.templates import heading, turn_to_align

__all__ = ["heading", "local_xy", "top_of", "turn_to_align", "turn_to_face_robot"]


def local_xy(world: World, host: str, local: tuple[float, float]) -> tuple[float, float]:
    """The table position of point ``local`` (object frame, scale 1) of object ``host``."""
    inst = world.object(host)
    p = world.object_pos(host) + world.object_mat(host) @ (np.array([*local, 0.0]) * inst.scale)
    return float(p[0]), float(p[1])


def turn_to_face_robot(world: World, obj: str, at: tuple[float, float] | None = None,
                       point: str | None = None) -> float:
    """The turn (within ±pi) after which ``obj``'s functional point faces the robot's base, once
    ``obj`` stands at ``at`` (default: where it is)."""
    inst = world.object(obj)
    d = CATALOG.get(inst.type_name).functional_point(point).direction
    out = math.atan2(d[1], d[0]) + heading(world, obj)
    pos = world.object_pos(obj) if at is None else at
    wanted = math.atan2(ROBOT_MOUNT[1] - pos[1], ROBOT_MOUNT[0] - pos[0])
    return wrap_angle(wanted - out)


def top_of(world: World, obj: str) -> float:
    """Height of ``obj``'s top (its catalog height, scaled, above its origin)."""
    inst = world.object(obj)
    return float(world.object_pos(obj)[2] + CATALOG.get(inst.type_name).size[2] * inst.scale)


