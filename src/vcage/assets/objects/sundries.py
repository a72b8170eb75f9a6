"""Desk and living-room sundries: a tissue box, a pen holder, a remote control and a glue stick."""

from __future__ import annotations

import math

from vcage.assets.annotations import (
    FOUR_SIDES,
    HALF_PI,
    RIM_DROP,
    S2,
    Annotations,
    Placement,
    grasp_pair,
    rim_grasps,
)
from vcage.assets.catalog import CATALOG, ObjectType
from vcage.assets.parts import VISUAL, WHITE, PartBuilder

# --- tissue box ---------------------------------------------------------------------------------
TISSUE = (0.12, 0.12, 0.13)


def _tissue_box(p: PartBuilder) -> None:
    sx, sy, sz = TISSUE
    p.box([sx / 2, sy / 2, sz / 2], [0, 0, sz / 2], name="box")
    p.box([0.035, 0.015, 0.0005], [0, 0, sz + 0.0005], (0.2, 0.2, 0.2, 1.0), name="opening", **VISUAL)
    p.box([0.025, 0.002, 0.012], [0, 0, sz + 0.012], WHITE, name="tissue", **VISUAL)


CATALOG.add_type(ObjectType(
    name="tissue_box", category="household", description="a cube-shaped box of tissues",
    size=(TISSUE[0], TISSUE[1], TISSUE[2] + 0.024), mass=0.15,
    colors={"blue": (0.4, 0.6, 0.85, 1.0), "green": (0.5, 0.75, 0.5, 1.0),
            "pink": (0.92, 0.65, 0.75, 1.0)},
    build=_tissue_box, tags=frozenset({"household", "obstacle"}),
))

# --- pen holder ---------------------------------------------------------------------------------
HOLDER_R, HOLDER_H, HOLDER_T, HOLDER_FLOOR = 0.04, 0.1, 0.004, 0.006


def _pen_holder(p: PartBuilder) -> None:
    p.open_cylinder(HOLDER_R, HOLDER_H, HOLDER_T, HOLDER_FLOOR)


_HOLDER_RIM_R = HOLDER_R - HOLDER_T / 2
CATALOG.add_type(ObjectType(
    name="pen_holder", category="container", description="a cylindrical desk pen holder",
    size=(2 * HOLDER_R, 2 * HOLDER_R, HOLDER_H), mass=0.12,
    colors={"black": (0.15, 0.15, 0.16, 1.0), "silver": (0.72, 0.73, 0.76, 1.0),
            "blue": (0.2, 0.35, 0.7, 1.0)},
    build=_pen_holder, tags=frozenset({"container", "graspable", "office"}),
    annotations=Annotations(
        grasps=rim_grasps(_HOLDER_RIM_R, HOLDER_H - RIM_DROP, FOUR_SIDES, HOLDER_T),
        # S2 is math.sqrt(0.5), one ulp above the containers' 1 / math.sqrt(2): kept, so the
        # half size (and every scene placed in a pen holder) stays as it was.
        placements=(Placement("inside", "in", (0, 0, HOLDER_FLOOR), ((HOLDER_R - HOLDER_T) * S2,) * 2,
                              HOLDER_H - HOLDER_FLOOR),),
    ),
))

# --- remote control -----------------------------------------------------------------------------
REMOTE = (0.045, 0.17, 0.02)


def _remote(p: PartBuilder) -> None:
    sx, sy, sz = REMOTE
    p.box([sx / 2, sy / 2, sz / 2], [0, 0, sz / 2], name="body")
    p.cylinder(0.005, 0.0005, [0, sy / 2 - 0.02, sz + 0.0005], (0.8, 0.15, 0.12, 1.0), name="power",
               **VISUAL)
    for i in range(4):
        for j in (-1, 0, 1):
            p.box([0.004, 0.003, 0.0005], [j * 0.012, 0.02 - i * 0.014, sz + 0.0005],
                  (0.55, 0.56, 0.58, 1.0), name=f"key{i}{j + 1}", **VISUAL)


CATALOG.add_type(ObjectType(
    name="remote", category="electronics", description="a TV remote control",
    size=(REMOTE[0], REMOTE[1], REMOTE[2] + 0.001), mass=0.1,
    colors={"black": (0.12, 0.12, 0.13, 1.0), "gray": (0.45, 0.46, 0.48, 1.0),
            "white": (0.9, 0.9, 0.9, 1.0)},
    build=_remote, tags=frozenset({"graspable", "electronics", "household"}),
    annotations=Annotations(grasps=grasp_pair("top", (0, 0, 0.02), REMOTE[0], yaw=HALF_PI, second=math.pi)),
))

# --- glue stick ---------------------------------------------------------------------------------
GLUE_R, GLUE_H, GLUE_CAP = 0.014, 0.1, 0.028


def _glue_stick(p: PartBuilder) -> None:
    body_h = GLUE_H - GLUE_CAP
    p.cylinder(GLUE_R, body_h / 2, [0, 0, body_h / 2], WHITE, name="body")
    p.cylinder(GLUE_R + 0.0005, GLUE_CAP / 2, [0, 0, body_h + GLUE_CAP / 2], name="cap")
    p.cylinder(GLUE_R + 0.0003, 0.015, [0, 0, body_h * 0.5], name="label", **VISUAL)


CATALOG.add_type(ObjectType(
    name="glue_stick", category="office", description="a glue stick standing upright",
    size=(2 * GLUE_R + 0.001, 2 * GLUE_R + 0.001, GLUE_H), mass=0.03,
    colors={"purple": (0.55, 0.25, 0.7, 1.0), "orange": (0.95, 0.5, 0.1, 1.0),
            "green": (0.25, 0.65, 0.3, 1.0)},
    build=_glue_stick, tags=frozenset({"graspable", "office", "cylindrical"}),
    annotations=Annotations(grasps=grasp_pair("top", (0, 0, 0.06), 2 * GLUE_R + 0.001)),
))
