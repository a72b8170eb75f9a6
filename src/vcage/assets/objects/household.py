"""Household things of RoboTwin's tasks: shoes and a shoe box, a pill bottle, a burger and fries,
a plastic box, a dustbin, a kitchen scale and a deck of playing cards.

Containers are a floor and four walls (see :mod:`.containers`); their ``inside`` placement is the
whole inner rectangle, which is what ``inside`` checks. Walls are low enough, or the containers
wide enough, that the open fingers fit beside what is put in.
"""

from __future__ import annotations

import math

from vcage.assets.annotations import HALF_PI, Annotations, Placement, grasp_pair
from vcage.assets.catalog import CATALOG, ObjectType
from vcage.assets.parts import DARK, VISUAL, PartBuilder

WHITE = (0.95, 0.95, 0.94, 1.0)


def _box_inside(half_x: float, half_y: float, floor: float, wall: float) -> Placement:
    return Placement("inside", "in", (0, 0, floor), (half_x, half_y), wall)


# --- shoe ---------------------------------------------------------------------------------------
SHOE = (0.15, 0.056, 0.052)  # toe towards +x
SHOE_SOLE = 0.012


def _shoe(p: PartBuilder) -> None:
    sx, sy, sz = SHOE
    p.box([sx / 2, sy / 2, SHOE_SOLE / 2], [0, 0, SHOE_SOLE / 2], (0.92, 0.92, 0.9, 1.0), name="sole")
    upper = sz - SHOE_SOLE
    p.box([0.045, sy / 2, upper / 2], [-0.025, 0, SHOE_SOLE + upper / 2], name="upper")
    p.box([0.028, sy / 2 - 0.002, 0.011], [0.045, 0, SHOE_SOLE + 0.011], name="toe")
    p.box([0.02, sy / 2 - 0.008, 0.0005], [-0.03, 0, sz + 0.0005], DARK, name="opening", **VISUAL)


CATALOG.add_type(ObjectType(
    name="shoe", category="clothing", description="a sneaker",
    size=(SHOE[0], SHOE[1], SHOE[2] + 0.001), mass=0.2,
    colors={"white": (0.9, 0.9, 0.9, 1.0), "black": (0.15, 0.15, 0.16, 1.0),
            "red": (0.78, 0.16, 0.14, 1.0), "blue": (0.2, 0.35, 0.7, 1.0)},
    build=_shoe, tags=frozenset({"graspable", "clothing"}), scale_range=(0.95, 1.05),
    annotations=Annotations(grasps=grasp_pair("upper", (-0.025, 0, 0.04), SHOE[1], second=math.pi)),
))

# --- shoe box -----------------------------------------------------------------------------------
SHOE_BOX_HX, SHOE_BOX_HY, SHOE_BOX_WALL, SHOE_BOX_T, SHOE_BOX_FLOOR = 0.1, 0.13, 0.04, 0.006, 0.005


def _shoe_box(p: PartBuilder) -> None:
    p.open_box(SHOE_BOX_HX, SHOE_BOX_HY, SHOE_BOX_WALL, SHOE_BOX_T, SHOE_BOX_FLOOR)


CATALOG.add_type(ObjectType(
    name="shoe_box", category="container", description="an open shoe box that holds a pair of shoes",
    size=(2 * (SHOE_BOX_HX + SHOE_BOX_T), 2 * (SHOE_BOX_HY + SHOE_BOX_T), SHOE_BOX_FLOOR + SHOE_BOX_WALL),
    mass=0.25,
    colors={"cardboard": (0.7, 0.53, 0.33, 1.0), "white": (0.9, 0.88, 0.84, 1.0),
            "orange": (0.92, 0.5, 0.15, 1.0)},
    build=_shoe_box, tags=frozenset({"container"}), scale_range=(1.0, 1.05),
    annotations=Annotations(
        placements=(_box_inside(SHOE_BOX_HX, SHOE_BOX_HY, SHOE_BOX_FLOOR, SHOE_BOX_WALL),)),
))

# --- pill bottle --------------------------------------------------------------------------------
PILL_R, PILL_BODY_H, PILL_CAP_H = 0.022, 0.058, 0.014


def _pill_bottle(p: PartBuilder) -> None:
    p.cylinder(PILL_R, PILL_BODY_H / 2, [0, 0, PILL_BODY_H / 2], name="body")
    p.cylinder(PILL_R + 0.001, PILL_CAP_H / 2, [0, 0, PILL_BODY_H + PILL_CAP_H / 2], WHITE, name="cap")
    p.cylinder(PILL_R + 0.0004, 0.014, [0, 0, PILL_BODY_H * 0.45], WHITE, name="label", **VISUAL)


_PILL_H = PILL_BODY_H + PILL_CAP_H
CATALOG.add_type(ObjectType(
    name="pill_bottle", category="household", description="a small medicine bottle with a white cap",
    size=(2 * PILL_R + 0.002, 2 * PILL_R + 0.002, _PILL_H), mass=0.06,
    colors={"orange": (0.9, 0.5, 0.12, 1.0), "brown": (0.45, 0.28, 0.14, 1.0),
            "white": (0.9, 0.9, 0.88, 1.0)},
    build=_pill_bottle, tags=frozenset({"graspable", "household", "cylindrical"}),
    annotations=Annotations(grasps=grasp_pair("body", (0, 0, round(_PILL_H - 0.04, 4)), 2 * PILL_R + 0.002)),
))

# --- burger -------------------------------------------------------------------------------------
BURGER_R = 0.03


def _burger(p: PartBuilder) -> None:
    bun = p.rgba
    p.cylinder(BURGER_R, 0.008, [0, 0, 0.008], bun, name="bun_bottom")
    p.cylinder(BURGER_R + 0.001, 0.006, [0, 0, 0.022], (0.35, 0.2, 0.1, 1.0), name="patty")
    p.cylinder(BURGER_R + 0.002, 0.001, [0, 0, 0.029], (0.35, 0.7, 0.25, 1.0), name="lettuce", **VISUAL)
    p.cylinder(BURGER_R, 0.009, [0, 0, 0.037], bun, name="bun_top")
    p.sphere(0.006, [0, 0, 0.043], bun, name="dome", **VISUAL)


CATALOG.add_type(ObjectType(
    name="burger", category="food", description="a hamburger",
    size=(2 * BURGER_R + 0.004, 2 * BURGER_R + 0.004, 0.049), mass=0.12,
    colors={"bun": (0.85, 0.6, 0.3, 1.0), "sesame": (0.8, 0.55, 0.28, 1.0)},
    build=_burger, tags=frozenset({"graspable", "food"}),
    annotations=Annotations(grasps=grasp_pair("top", (0, 0, 0.03), 2 * BURGER_R + 0.002)),
))

# --- fries --------------------------------------------------------------------------------------
FRIES = (0.022, 0.03, 0.03)  # half extents of the carton


def _fries(p: PartBuilder) -> None:
    fx, fy, fz = FRIES
    p.box([fx, fy, fz], [0, 0, fz], name="carton")
    yellow = (0.98, 0.82, 0.3, 1.0)
    for k, (x, y, h) in enumerate(((-0.01, -0.015, 0.016), (0.0, 0.0, 0.02), (0.01, 0.012, 0.014),
                                   (-0.008, 0.016, 0.018), (0.009, -0.012, 0.017))):
        p.box([0.003, 0.003, h / 2], [x, y, 2 * fz + h / 2], yellow, name=f"fry{k}", **VISUAL)


CATALOG.add_type(ObjectType(
    name="fries", category="food", description="french fries in a carton",
    size=(2 * FRIES[0], 2 * FRIES[1], 2 * FRIES[2] + 0.02), mass=0.1,
    colors={"red": (0.82, 0.12, 0.1, 1.0), "yellow": (0.95, 0.78, 0.15, 1.0)},
    build=_fries, tags=frozenset({"graspable", "food"}),
    annotations=Annotations(grasps=grasp_pair("carton", (0, 0, 0.045), 2 * FRIES[0], yaw=HALF_PI,
                                              second=math.pi)),
))

# --- plastic box --------------------------------------------------------------------------------
PBOX_HX, PBOX_HY, PBOX_WALL, PBOX_T, PBOX_FLOOR = 0.09, 0.12, 0.045, 0.005, 0.005


def _plastic_box(p: PartBuilder) -> None:
    p.open_box(PBOX_HX, PBOX_HY, PBOX_WALL, PBOX_T, PBOX_FLOOR)


CATALOG.add_type(ObjectType(
    name="plastic_box", category="container", description="a shallow open plastic storage box",
    size=(2 * (PBOX_HX + PBOX_T), 2 * (PBOX_HY + PBOX_T), PBOX_FLOOR + PBOX_WALL), mass=0.2,
    colors={"clear": (0.75, 0.82, 0.88, 1.0), "blue": (0.3, 0.5, 0.85, 1.0),
            "green": (0.35, 0.7, 0.45, 1.0)},
    build=_plastic_box, tags=frozenset({"container"}), scale_range=(1.0, 1.05),
    annotations=Annotations(placements=(_box_inside(PBOX_HX, PBOX_HY, PBOX_FLOOR, PBOX_WALL),)),
))

# --- dustbin ------------------------------------------------------------------------------------
BIN_HX, BIN_HY, BIN_WALL, BIN_T, BIN_FLOOR = 0.085, 0.09, 0.1, 0.006, 0.006


def _dustbin(p: PartBuilder) -> None:
    p.open_box(BIN_HX, BIN_HY, BIN_WALL, BIN_T, BIN_FLOOR)
    rim = tuple(0.7 * c for c in p.rgba[:3]) + (1.0,)
    for sgn, side in ((1, "n"), (-1, "s")):
        p.box([BIN_HX + BIN_T, 0.0005, 0.006],
              [0, sgn * (BIN_HY + BIN_T + 0.0005), BIN_FLOOR + BIN_WALL - 0.006], rim,
              name=f"rim_{side}", **VISUAL)


CATALOG.add_type(ObjectType(
    name="dustbin", category="container", description="a square open dustbin",
    size=(2 * (BIN_HX + BIN_T), 2 * (BIN_HY + BIN_T + 0.001), BIN_FLOOR + BIN_WALL), mass=0.4,
    colors={"gray": (0.5, 0.52, 0.55, 1.0), "green": (0.25, 0.55, 0.3, 1.0),
            "blue": (0.2, 0.35, 0.7, 1.0)},
    build=_dustbin, tags=frozenset({"container", "household"}), scale_range=(1.0, 1.05),
    annotations=Annotations(placements=(_box_inside(BIN_HX, BIN_HY, BIN_FLOOR, BIN_WALL),)),
))

# --- kitchen scale ------------------------------------------------------------------------------
SCALE_BODY = (0.07, 0.075, 0.01)  # half extents of the housing
SCALE_PLATFORM = (0.06, 0.06, 0.003)


def _kitchen_scale(p: PartBuilder) -> None:
    bx, by, bz = SCALE_BODY
    p.box([bx, by, bz], [0, 0, bz], name="housing")
    px, py, pz = SCALE_PLATFORM
    p.box([px, py, pz], [0, 0.01, 2 * bz + pz], (0.8, 0.8, 0.82, 1.0), name="platform")
    p.box([0.025, 0.006, 0.0005], [0, -by + 0.008, 2 * bz + 0.0005], (0.3, 0.45, 0.35, 1.0),
          name="display", **VISUAL)


_SCALE_TOP = 2 * SCALE_BODY[2] + 2 * SCALE_PLATFORM[2]
CATALOG.add_type(ObjectType(
    name="kitchen_scale", category="kitchen", description="a flat digital kitchen scale",
    size=(2 * SCALE_BODY[0], 2 * SCALE_BODY[1], _SCALE_TOP), mass=0.3,
    colors={"white": (0.92, 0.92, 0.9, 1.0), "black": (0.15, 0.15, 0.16, 1.0),
            "silver": (0.72, 0.73, 0.76, 1.0)},
    build=_kitchen_scale, tags=frozenset({"flat", "kitchen", "support"}),
    annotations=Annotations(placements=(Placement("top", "on", (0, 0.01, _SCALE_TOP),
                                                  (SCALE_PLATFORM[0] - 0.008, SCALE_PLATFORM[1] - 0.008)),)),
))

# --- deck of playing cards ----------------------------------------------------------------------
DECK = (0.063, 0.088, 0.018)


def _card_deck(p: PartBuilder) -> None:
    sx, sy, sz = DECK
    p.box([sx / 2, sy / 2, sz / 2], [0, 0, sz / 2], WHITE, name="cards")
    p.box([sx / 2 - 0.004, sy / 2 - 0.004, 0.0001], [0, 0, sz + 0.0001], name="back", **VISUAL)
    for sgn, side in ((1, "e"), (-1, "w")):
        p.box([0.0001, sy / 2 - 0.002, sz / 2 - 0.001], [sgn * (sx / 2 + 0.0001), 0, sz / 2],
              (0.85, 0.85, 0.83, 1.0), name=f"edge_{side}", **VISUAL)


CATALOG.add_type(ObjectType(
    name="card_deck", category="toy", description="a deck of playing cards lying face down",
    size=(DECK[0], DECK[1], DECK[2] + 0.0002), mass=0.1,
    colors={"red": (0.75, 0.12, 0.15, 1.0), "blue": (0.15, 0.25, 0.65, 1.0),
            "green": (0.15, 0.5, 0.3, 1.0)},
    build=_card_deck, tags=frozenset({"flat", "pushable", "toy"}), scale_range=(0.95, 1.05),
))
