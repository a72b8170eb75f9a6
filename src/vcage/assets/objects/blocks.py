"""Blocks and simple geometric toys."""

from __future__ import annotations

import math

from vcage.assets.annotations import Annotations, Grasp, Placement, StableOrientation
from vcage.assets.catalog import CATALOG, ObjectType
from vcage.assets.parts import PartBuilder

BLOCK_COLORS = {
    "red": (0.85, 0.15, 0.12, 1.0),
    "green": (0.15, 0.7, 0.2, 1.0),
    "blue": (0.15, 0.3, 0.85, 1.0),
    "yellow": (0.95, 0.8, 0.1, 1.0),
    "orange": (0.95, 0.5, 0.1, 1.0),
    "purple": (0.55, 0.2, 0.7, 1.0),
}
BLOCK = 0.045  # edge length of a cube block


def _cube(p: PartBuilder) -> None:
    p.box([BLOCK / 2] * 3, [0, 0, BLOCK / 2], name="body")


CATALOG.add_type(ObjectType(
    name="block", category="toy", description="a small wooden cube block",
    size=(BLOCK, BLOCK, BLOCK), mass=0.06, colors=BLOCK_COLORS, build=_cube,
    tags=frozenset({"block", "stackable", "graspable", "colored"}), scale_range=(0.95, 1.05), any_face=True,
    annotations=Annotations(
        grasps=tuple(Grasp(f"top_{i}", (0, 0, BLOCK / 2), yaw=i * math.pi / 2, width=BLOCK)
                     for i in range(2)),
        placements=(Placement("top", "on", (0, 0, BLOCK), (BLOCK / 2, BLOCK / 2)),),
        stable_orientations=(StableOrientation("upright"),
                             StableOrientation("side", (0.7071068, 0.7071068, 0.0, 0.0))),
    ),
))
