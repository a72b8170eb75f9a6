"""Where a target's placement region is now, for the skills that put things there and the oracle
that judges them: a drawer's inside rides its slide joint, and a cube's surface is the face that is
up (a block knocked onto its side still carries what is put on it)."""

from __future__ import annotations

import numpy as np

from vcage.assets.catalog import CATALOG
from vcage.sim.world import World
from vcage.skills.drawers import slid


def placement_frame(world: World, target: str,
                    placement: str | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Centre (world), rotation (its z axis the surface's normal), half size and wall height of
    ``target``'s placement region ``placement`` (None: its first) where it is now."""
    inst = world.object(target)
    otype = CATALOG.get(inst.type_name)
    place = otype.placement(placement)
    rot = world.object_mat(target)
    local = np.asarray(place.pos) * inst.scale + slid(world, target, place.joint)
    center = world.object_pos(target) + rot @ local
    if otype.any_face:  # the face up now: the cube's centre plus half a side along the axis nearest up
        side = place.pos[2] * inst.scale
        middle = center - rot[:, 2] * side / 2
        k = int(np.argmax(np.abs(rot[2])))
        up = rot[:, k] * np.sign(rot[2, k])
        x = rot[:, (k + 1) % 3]
        rot = np.column_stack([x, np.cross(up, x), up])
        center = middle + up * side / 2
    return center, rot, np.asarray(place.half_size) * inst.scale, place.wall_height * inst.scale
