"""Hollow and flat things that hold other objects: cups, mugs, bowls, baskets, pots, plates, trays.

Every container is a floor plus thin walls (a ring of boxes for round ones, four boxes for
rectangular ones), so what is dropped in really stays in. ``in`` placements give the floor centre,
the inscribed square of the floor (round) or the inner rectangle, and the inner wall height.
Rim grasps pinch the wall between the fingers, so their width is the wall thickness.
"""

from __future__ import annotations

import math

from vcage.assets.annotations import (
    FOUR_SIDES,
    HALF_PI,
    RIM_DROP,
    Annotations,
    FunctionalPoint,
    Grasp,
    Placement,
    StableOrientation,
    rim_grasps,
)
from vcage.assets.catalog import CATALOG, ObjectType
from vcage.assets.parts import PartBuilder

INV_SQRT2 = 1 / math.sqrt(2)


def _round_inside(radius: float, thickness: float, floor: float, height: float) -> Placement:
    """The ``inside`` of a round container: the square inscribed in the floor, walls up to ``height``."""
    return Placement("inside", "in", (0, 0, floor), ((radius - thickness) * INV_SQRT2,) * 2, height - floor)


def _rect_rim_grasps(half_x: float, half_y: float, thickness: float, z: float) -> tuple[Grasp, ...]:
    """Grasps pinching the four walls of a rectangular container at their middles."""
    wy, wx = half_y + thickness / 2, half_x + thickness / 2
    return (
        Grasp("rim", (0.0, wy, z), yaw=0.0, width=thickness),
        Grasp("rim_1", (0.0, -wy, z), yaw=0.0, width=thickness),
        Grasp("rim_2", (wx, 0.0, z), yaw=HALF_PI, width=thickness),
        Grasp("rim_3", (-wx, 0.0, z), yaw=HALF_PI, width=thickness),
    )


def _open_box_annotations(half_x: float, half_y: float, thickness: float, floor: float, wall: float,
                          drop: float = RIM_DROP) -> Annotations:
    """A rectangular container's rim grasps (``drop`` below the top of its walls) and its inner
    rectangle as the ``inside`` placement."""
    return Annotations(
        grasps=_rect_rim_grasps(half_x, half_y, thickness, floor + wall - drop),
        placements=(Placement("inside", "in", (0, 0, floor), (half_x, half_y), wall),),
    )

# --- cup ----------------------------------------------------------------------------------------
CUP_R, CUP_H, CUP_T, CUP_FLOOR = 0.035, 0.09, 0.004, 0.006


def _cup(p: PartBuilder) -> None:
    p.open_cylinder(CUP_R, CUP_H, CUP_T, CUP_FLOOR)


CATALOG.add_type(ObjectType(
    name="cup", category="container", description="a plain drinking cup",
    size=(2 * CUP_R, 2 * CUP_R, CUP_H), mass=0.1,
    colors={"white": (0.92, 0.92, 0.9, 1.0), "blue": (0.2, 0.4, 0.8, 1.0),
            "green": (0.3, 0.65, 0.35, 1.0), "red": (0.8, 0.2, 0.18, 1.0)},
    build=_cup, tags=frozenset({"container", "graspable", "kitchen"}),
    annotations=Annotations(
        grasps=rim_grasps(CUP_R - CUP_T / 2, CUP_H - RIM_DROP, FOUR_SIDES, CUP_T),
        placements=(_round_inside(CUP_R, CUP_T, CUP_FLOOR, CUP_H),),
    ),
))

# --- mug ----------------------------------------------------------------------------------------
MUG_R, MUG_H, MUG_T, MUG_FLOOR = 0.04, 0.095, 0.004, 0.006
MUG_HANDLE_X = 0.064  # centre of the handle's outer bar
MUG_HANDLE_Z = 0.053
MUG_HANDLE_W = 0.012  # extent of the handle along y
MUG_HOLE_X = (MUG_R + MUG_HANDLE_X - 0.004) / 2  # the middle of the handle's opening


def _mug(p: PartBuilder) -> None:
    p.open_cylinder(MUG_R, MUG_H, MUG_T, MUG_FLOOR)
    hw = MUG_HANDLE_W / 2
    bar_x = (MUG_R - 0.002 + MUG_HANDLE_X) / 2
    bar_half = (MUG_HANDLE_X - MUG_R + 0.002) / 2
    p.box([bar_half, hw, 0.004], [bar_x, 0, MUG_HANDLE_Z + 0.025], name="handle_top")
    p.box([bar_half, hw, 0.004], [bar_x, 0, MUG_HANDLE_Z - 0.025], name="handle_bottom")
    p.box([0.004, hw, 0.029], [MUG_HANDLE_X, 0, MUG_HANDLE_Z], name="handle")


CATALOG.add_type(ObjectType(
    name="mug", category="container", description="a ceramic coffee mug with a handle",
    size=(2 * (MUG_HANDLE_X + 0.004), 2 * MUG_R, MUG_H), mass=0.2,
    colors={"red": (0.78, 0.16, 0.14, 1.0), "white": (0.93, 0.93, 0.9, 1.0),
            "yellow": (0.93, 0.78, 0.2, 1.0), "black": (0.12, 0.12, 0.13, 1.0)},
    build=_mug, tags=frozenset({"container", "graspable", "kitchen"}),
    annotations=Annotations(
        grasps=(Grasp("handle", (MUG_HANDLE_X, 0, MUG_HANDLE_Z), yaw=0.0, width=MUG_HANDLE_W),
                *rim_grasps(MUG_R - MUG_T / 2, MUG_H - RIM_DROP, FOUR_SIDES[1:], MUG_T)),
        placements=(_round_inside(MUG_R, MUG_T, MUG_FLOOR, MUG_H),),
        # the middle of the handle's opening, which a rack's peg goes through (skills.hanging)
        functional_points=(FunctionalPoint("handle", "loop", (MUG_HOLE_X, 0, MUG_HANDLE_Z),
                                           direction=(1.0, 0.0, 0.0)),),
    ),
))

# --- bowl (flared, nests) -----------------------------------------------------------------------
BOWL_R0, BOWL_R1, BOWL_H, BOWL_T, BOWL_FLOOR = 0.036, 0.07, 0.055, 0.004, 0.004
BOWL_FRICTION = 0.15
# Types whose flared walls let one go inside another of the type, and how much smaller (scale) the
# inner one must be
NESTING = frozenset({"bowl"})
NEST_RATIO = 0.92
_BOWL_TILT = math.atan2(BOWL_R1 - BOWL_R0, BOWL_H - BOWL_FLOOR)
_BOWL_OUT = BOWL_R1 + BOWL_T * math.cos(_BOWL_TILT)  # outer radius at the rim


def _bowl_inner_r(z: float) -> float:
    return BOWL_R0 + (z - BOWL_FLOOR) * math.tan(_BOWL_TILT)


def _bowl(p: PartBuilder) -> None:
    floor = p.cylinder(BOWL_R0 + BOWL_T, BOWL_FLOOR / 2, [0, 0, BOWL_FLOOR / 2], name="floor")
    walls = p.flared_ring(BOWL_R0, BOWL_R1, BOWL_FLOOR, BOWL_H, BOWL_T, segments=16)
    # Glazed ceramic is slippery on itself: MuJoCo takes the larger friction of a contact pair, so
    # this only matters bowl-on-bowl, where a bowl put in off-centre slides down and nests level.
    for geom in (floor, *walls):
        geom.friction = [BOWL_FRICTION * p.friction, 0.005, 0.0001]


_BOWL_GRASP_Z = BOWL_H - 0.008
_BOWL_GRASP_R = _bowl_inner_r(_BOWL_GRASP_Z) + BOWL_T / 2
# The fingers reach 35 mm below the grasp point: the inner one meets the wall lower down.
_BOWL_GRASP_W = _BOWL_OUT - _bowl_inner_r(_BOWL_GRASP_Z - 0.035)

CATALOG.add_type(ObjectType(
    name="bowl", category="container", description="a round bowl with flared sides",
    size=(2 * _BOWL_OUT + 0.004, 2 * _BOWL_OUT + 0.004, BOWL_H), mass=0.15,
    colors={"white": (0.93, 0.92, 0.88, 1.0), "blue": (0.22, 0.45, 0.75, 1.0),
            "green": (0.45, 0.7, 0.4, 1.0), "orange": (0.92, 0.55, 0.2, 1.0)},
    build=_bowl, tags=frozenset({"container", "graspable", "kitchen", "stackable"}),
    annotations=Annotations(
        grasps=rim_grasps(_BOWL_GRASP_R, _BOWL_GRASP_Z, FOUR_SIDES, round(_BOWL_GRASP_W, 4)),
        placements=(Placement("inside", "in", (0, 0, BOWL_FLOOR), (BOWL_R0 * INV_SQRT2,) * 2,
                              BOWL_H - BOWL_FLOOR),),
    ),
))

# --- basket -------------------------------------------------------------------------------------
BASKET_HX, BASKET_HY, BASKET_WALL, BASKET_T, BASKET_FLOOR = 0.09, 0.07, 0.06, 0.006, 0.006


def _basket(p: PartBuilder) -> None:
    t = BASKET_T
    p.open_box(BASKET_HX, BASKET_HY, BASKET_WALL, t, BASKET_FLOOR)
    # Darker bands to suggest a weave (visual only).
    band = tuple(0.7 * c for c in p.rgba[:3]) + (1.0,)
    for k, z in enumerate((0.022, 0.046)):
        for sgn in (1, -1):
            p.box([BASKET_HX + t, 0.0005, 0.004], [0, sgn * (BASKET_HY + t + 0.0005), z], band,
                  name=f"band{k}{'n' if sgn > 0 else 's'}", contype=0, conaffinity=0)


CATALOG.add_type(ObjectType(
    name="basket", category="container", description="a rectangular woven basket",
    size=(2 * (BASKET_HX + BASKET_T), 2 * (BASKET_HY + BASKET_T), BASKET_FLOOR + BASKET_WALL),
    mass=0.2,
    colors={"wicker": (0.72, 0.55, 0.33, 1.0), "brown": (0.5, 0.34, 0.2, 1.0),
            "gray": (0.55, 0.55, 0.55, 1.0)},
    build=_basket, tags=frozenset({"container", "graspable"}),
    annotations=_open_box_annotations(BASKET_HX, BASKET_HY, BASKET_T, BASKET_FLOOR, BASKET_WALL),
))

# --- pot ----------------------------------------------------------------------------------------
POT_R, POT_H, POT_T, POT_FLOOR = 0.1, 0.1, 0.005, 0.006
POT_HANDLE = (0.018, 0.02, 0.006)  # half extents of a side handle tab
POT_HANDLE_Y = POT_R + POT_HANDLE[1] - 0.004
POT_HANDLE_Z = POT_H - 0.012


def _pot(p: PartBuilder) -> None:
    p.open_cylinder(POT_R, POT_H, POT_T, POT_FLOOR, segments=20)
    dark = (0.12, 0.12, 0.12, 1.0)
    p.box(POT_HANDLE, [0, POT_HANDLE_Y, POT_HANDLE_Z], dark, name="handle_left")
    p.box(POT_HANDLE, [0, -POT_HANDLE_Y, POT_HANDLE_Z], dark, name="handle_right")


_POT_GRASP_Y = POT_HANDLE_Y + 0.004
CATALOG.add_type(ObjectType(
    name="pot", category="container", description="a cooking pot with two side handles",
    size=(2 * POT_R, 2 * (POT_HANDLE_Y + POT_HANDLE[1]), POT_H), mass=0.4,
    colors={"steel": (0.7, 0.72, 0.75, 1.0), "red": (0.72, 0.15, 0.12, 1.0),
            "blue": (0.2, 0.32, 0.6, 1.0)},
    build=_pot, tags=frozenset({"container", "graspable", "kitchen"}),
    annotations=Annotations(
        grasps=(Grasp("handle_left", (0, _POT_GRASP_Y, POT_HANDLE_Z), yaw=HALF_PI,
                      width=2 * POT_HANDLE[0]),
                Grasp("handle_right", (0, -_POT_GRASP_Y, POT_HANDLE_Z), yaw=HALF_PI,
                      width=2 * POT_HANDLE[0])),
        placements=(_round_inside(POT_R, POT_T, POT_FLOOR, POT_H),),
    ),
))

# --- plate --------------------------------------------------------------------------------------
PLATE_R0, PLATE_R1, PLATE_H, PLATE_FLOOR, PLATE_T = 0.075, 0.1, 0.018, 0.004, 0.003


def _plate(p: PartBuilder) -> None:
    p.cylinder(PLATE_R0 + PLATE_T, PLATE_FLOOR / 2, [0, 0, PLATE_FLOOR / 2], name="floor")
    p.flared_ring(PLATE_R0, PLATE_R1, PLATE_FLOOR, PLATE_H, PLATE_T, segments=24, name="rim")


CATALOG.add_type(ObjectType(
    name="plate", category="tableware", description="a round dinner plate",
    size=(2 * PLATE_R1 + 0.008, 2 * PLATE_R1 + 0.008, PLATE_H), mass=0.25,
    colors={"white": (0.95, 0.95, 0.93, 1.0), "cream": (0.94, 0.9, 0.78, 1.0),
            "blue": (0.45, 0.6, 0.85, 1.0)},
    build=_plate, tags=frozenset({"flat", "kitchen", "tableware", "stackable", "support"}),
    annotations=Annotations(
        placements=(Placement("top", "on", (0, 0, PLATE_FLOOR), (PLATE_R0 * INV_SQRT2,) * 2),),
    ),
))

# --- tray ---------------------------------------------------------------------------------------
TRAY_HX, TRAY_HY, TRAY_WALL, TRAY_T, TRAY_FLOOR = 0.14, 0.09, 0.035, 0.006, 0.005


def _tray(p: PartBuilder) -> None:
    p.open_box(TRAY_HX, TRAY_HY, TRAY_WALL, TRAY_T, TRAY_FLOOR)


CATALOG.add_type(ObjectType(
    name="tray", category="container", description="a shallow rectangular serving tray",
    size=(2 * (TRAY_HX + TRAY_T), 2 * (TRAY_HY + TRAY_T), TRAY_FLOOR + TRAY_WALL), mass=0.2,
    colors={"wood": (0.66, 0.48, 0.3, 1.0), "black": (0.15, 0.15, 0.16, 1.0),
            "white": (0.9, 0.9, 0.88, 1.0)},
    build=_tray, tags=frozenset({"container", "graspable", "kitchen"}),
    annotations=_open_box_annotations(TRAY_HX, TRAY_HY, TRAY_T, TRAY_FLOOR, TRAY_WALL, drop=0.008),
))

# --- open box -----------------------------------------------------------------------------------
BOX_HX, BOX_HY, BOX_WALL, BOX_T, BOX_FLOOR = 0.06, 0.05, 0.08, 0.005, 0.005


def _box(p: PartBuilder) -> None:
    t = BOX_T
    p.open_box(BOX_HX, BOX_HY, BOX_WALL, t, BOX_FLOOR)
    tape = (0.8, 0.72, 0.5, 1.0)
    for sgn, side in ((1, "e"), (-1, "w")):  # packing-tape strips over the short walls
        p.box([0.0005, 0.012, 0.02], [sgn * (BOX_HX + t + 0.0005), 0, BOX_FLOOR + BOX_WALL - 0.02],
              tape, name=f"tape_{side}", contype=0, conaffinity=0)


CATALOG.add_type(ObjectType(
    name="box", category="container", description="an open cardboard box",
    size=(2 * (BOX_HX + BOX_T), 2 * (BOX_HY + BOX_T), BOX_FLOOR + BOX_WALL), mass=0.12,
    colors={"cardboard": (0.7, 0.53, 0.33, 1.0), "white": (0.9, 0.88, 0.84, 1.0)},
    build=_box, tags=frozenset({"container", "graspable"}),
    annotations=_open_box_annotations(BOX_HX, BOX_HY, BOX_T, BOX_FLOOR, BOX_WALL),
))

# --- coaster ------------------------------------------------------------------------------------
COASTER_R, COASTER_H = 0.05, 0.005


def _coaster(p: PartBuilder) -> None:
    p.cylinder(COASTER_R, COASTER_H / 2, [0, 0, COASTER_H / 2], name="body")


CATALOG.add_type(ObjectType(
    name="coaster", category="tableware", description="a round drink coaster",
    size=(2 * COASTER_R, 2 * COASTER_R, COASTER_H), mass=0.02,
    colors={"cork": (0.72, 0.56, 0.38, 1.0), "black": (0.14, 0.14, 0.14, 1.0),
            "green": (0.3, 0.55, 0.35, 1.0)},
    build=_coaster, tags=frozenset({"flat", "kitchen", "tableware", "support"}),
    annotations=Annotations(
        placements=(Placement("top", "on", (0, 0, COASTER_H), (COASTER_R * INV_SQRT2,) * 2),),
        stable_orientations=(StableOrientation("upright"),
                             StableOrientation("flipped", (0.0, 1.0, 0.0, 0.0))),
    ),
))
