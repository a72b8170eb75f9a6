"""Office and household things: computer mouse and pad, phone and stand, cards, books, markers,
tape, a display stand, toys (dice, toy car, tennis ball, Rubik's cube), a tissue box, a pen holder,
a remote control and a glue stick.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

from vcage.assets.annotations import (
    FOUR_SIDES,
    HALF_PI,
    RIM_DROP,
    Annotations,
    Grasp,
    Placement,
    StableOrientation,
    grasp_pair,
    rim_grasps,
)
from vcage.assets.catalog import CATALOG, ObjectType
from vcage.assets.parts import DARK, VISUAL, X_AXIS_QUAT, Y_AXIS_QUAT, PartBuilder
from vcage.geometry import mat_to_quat, rot_y

S2 = math.sqrt(0.5)
WHITE = (0.95, 0.95, 0.94, 1.0)


def _cube_faces(half: float) -> Iterator[tuple[str, np.ndarray, np.ndarray, np.ndarray]]:
    """The faces of a cube of half edge ``half`` resting on z=0: name, centre, two in-face axes."""
    c = np.array([0.0, 0.0, half])
    ex, ey, ez = np.eye(3)
    yield "top", c + half * ez, ex, ey
    yield "bottom", c - half * ez, ex, ey
    yield "east", c + half * ex, ey, ez
    yield "west", c - half * ex, ey, ez
    yield "north", c + half * ey, ex, ez
    yield "south", c - half * ey, ex, ez


# --- computer mouse -----------------------------------------------------------------------------
MOUSE = (0.106, 0.058, 0.04)


def _mouse(p: PartBuilder) -> None:
    sx, sy, sz = MOUSE
    p.box([sx / 2 - 0.006, sy / 2 - 0.001, 0.004], [0, 0, 0.004], name="base")
    hump_r, side_r = sz / 2, 0.014  # a high middle capsule flanked by two lower ones
    p.capsule(hump_r, sx / 2 - hump_r, [0, 0, hump_r], name="shell", quat=X_AXIS_QUAT)
    for k, y in enumerate((sy / 2 - side_r, side_r - sy / 2)):
        p.capsule(side_r, sx / 2 - hump_r - 0.006, [-0.003, y, side_r], name=f"side{k}", quat=X_AXIS_QUAT)
    p.box([0.008, 0.0004, 0.0008], [0.026, 0, sz - 0.0005], DARK, name="split", **VISUAL)
    p.cylinder(0.003, 0.004, [0.03, 0, sz - 0.003], DARK, name="wheel", quat=Y_AXIS_QUAT, **VISUAL)


CATALOG.add_type(ObjectType(
    name="mouse", category="electronics", description="a computer mouse",
    size=MOUSE, mass=0.08,
    colors={"black": (0.16, 0.16, 0.17, 1.0), "white": (0.9, 0.9, 0.9, 1.0),
            "gray": (0.55, 0.56, 0.58, 1.0)},
    build=_mouse, tags=frozenset({"graspable", "office", "electronics"}),
    annotations=Annotations(grasps=grasp_pair("top", (0, 0, 0.022), MOUSE[1], second=math.pi)),
    top_relief=0.006,  # its dome: 6.1-7.1 mm rendered at four headings
))

# --- mouse pad ----------------------------------------------------------------------------------
MOUSE_PAD = (0.2, 0.16, 0.004)


def _mouse_pad(p: PartBuilder) -> None:
    sx, sy, sz = MOUSE_PAD
    p.box([sx / 2, sy / 2, sz / 2], [0, 0, sz / 2], name="pad")


CATALOG.add_type(ObjectType(
    name="mouse_pad", category="office", description="a flat mouse pad",
    size=MOUSE_PAD, mass=0.05,
    colors={"black": (0.1, 0.1, 0.11, 1.0), "blue": (0.15, 0.25, 0.55, 1.0),
            "gray": (0.4, 0.42, 0.45, 1.0), "red": (0.6, 0.12, 0.12, 1.0)},
    build=_mouse_pad, tags=frozenset({"flat", "office", "support"}),
    annotations=Annotations(
        placements=(Placement("top", "on", (0, 0, MOUSE_PAD[2]),
                              (MOUSE_PAD[0] / 2 - 0.01, MOUSE_PAD[1] / 2 - 0.01)),),
    ),
))

# --- phone --------------------------------------------------------------------------------------
PHONE = (0.064, 0.135, 0.01)  # narrow enough for the gripper across its short side


def _phone(p: PartBuilder) -> None:
    sx, sy, sz = PHONE
    p.box([sx / 2, sy / 2, sz / 2], [0, 0, sz / 2], name="body")
    p.box([sx / 2 - 0.003, sy / 2 - 0.008, 0.0003], [0, 0, sz + 0.0003], (0.05, 0.06, 0.08, 1.0),
          name="screen", **VISUAL)


CATALOG.add_type(ObjectType(
    name="phone", category="electronics", description="a smartphone lying screen up",
    size=(PHONE[0], PHONE[1], PHONE[2] + 0.0006), mass=0.15,
    colors={"black": (0.15, 0.15, 0.16, 1.0), "silver": (0.75, 0.76, 0.78, 1.0),
            "blue": (0.25, 0.4, 0.65, 1.0), "pink": (0.9, 0.65, 0.7, 1.0)},
    build=_phone, tags=frozenset({"graspable", "flat", "electronics", "office"}),
    annotations=Annotations(
        grasps=grasp_pair("top", (0, 0, PHONE[2] / 2), PHONE[0], yaw=HALF_PI, second=math.pi),
    ),
))

# --- phone stand --------------------------------------------------------------------------------
STAND_SLOPE = 0.35  # rad: the slanted back rises towards -x
STAND_HALF_Y = 0.07
STAND_RAMP = (0.05, 0.01)  # half length along the slope, half thickness
STAND_FRONT = (0.042, 0.02)  # x, z of the ramp's low front edge (top surface)
STAND_LIP = 0.012  # how far the lip rises above the ramp's front edge
_SLOPE_DIR = np.array([math.cos(STAND_SLOPE), -math.sin(STAND_SLOPE)])  # down the slope (x, z)
_SLOPE_N = np.array([math.sin(STAND_SLOPE), math.cos(STAND_SLOPE)])  # surface normal (x, z)
_RAMP_TOP = np.array(STAND_FRONT) - STAND_RAMP[0] * _SLOPE_DIR  # centre of the top surface
_RAMP_BACK = np.array(STAND_FRONT) - 2 * STAND_RAMP[0] * _SLOPE_DIR  # high back edge
_STAND_BACK_X = float(_RAMP_BACK[0] - 2 * STAND_RAMP[1] * _SLOPE_N[0])


def _phone_stand(p: PartBuilder) -> None:
    hy = STAND_HALF_Y
    fx, fz = STAND_FRONT
    p.box([(fx - _STAND_BACK_X) / 2 + 0.003, hy, 0.004], [(fx + _STAND_BACK_X) / 2 + 0.003, 0, 0.004],
          name="base")
    centre = _RAMP_TOP - STAND_RAMP[1] * _SLOPE_N
    p.box([STAND_RAMP[0], hy, STAND_RAMP[1]], [centre[0], 0, centre[1]], name="back",
          quat=mat_to_quat(rot_y(STAND_SLOPE)).tolist())
    support_top = float(_RAMP_BACK[1]) - 0.01
    p.box([0.012, hy, support_top / 2], [_STAND_BACK_X + 0.012, 0, support_top / 2], name="support")
    lip_top = fz + STAND_LIP
    p.box([0.003, hy, lip_top / 2], [fx + 0.003, 0, lip_top / 2], DARK, name="lip")


_SLOT_X = float(_RAMP_TOP[0])
CATALOG.add_type(ObjectType(
    name="phone_stand", category="office", description="a phone stand with a slanted back and a lip",
    size=(2 * max(STAND_FRONT[0] + 0.006, -_STAND_BACK_X), 2 * STAND_HALF_Y, round(float(_RAMP_BACK[1]), 4)),
    mass=0.12,
    colors={"white": (0.92, 0.92, 0.9, 1.0), "black": (0.18, 0.18, 0.2, 1.0),
            "wood": (0.66, 0.48, 0.3, 1.0)},
    build=_phone_stand, tags=frozenset({"office", "support", "stand"}),
    annotations=Annotations(
        placements=(Placement("slot", "on", (round(_SLOT_X, 4), 0.0, round(float(_RAMP_TOP[1]), 4)),
                              (round(STAND_RAMP[0] * math.cos(STAND_SLOPE), 4), STAND_HALF_Y - 0.005),
                              slope=STAND_SLOPE),),
    ),
))

# --- playing card -------------------------------------------------------------------------------
CARD = (0.063, 0.088, 0.003)


def _playing_card(p: PartBuilder) -> None:
    sx, sy, sz = CARD
    p.box([sx / 2, sy / 2, sz / 2], [0, 0, sz / 2], WHITE, name="card")
    p.box([sx / 2 - 0.004, sy / 2 - 0.004, 0.0001], [0, 0, sz + 0.0001], name="back", **VISUAL)


CATALOG.add_type(ObjectType(
    name="playing_card", category="toy", description="a playing card lying face down",
    size=CARD, mass=0.002,
    colors={"red": (0.75, 0.12, 0.15, 1.0), "blue": (0.15, 0.25, 0.65, 1.0)},
    build=_playing_card, tags=frozenset({"flat", "pushable", "toy"}), scale_range=(0.95, 1.05),
))

# --- book ---------------------------------------------------------------------------------------
BOOK = (0.15, 0.21, 0.03)
BOOK_COVER = 0.002


def _book(p: PartBuilder) -> None:
    sx, sy, sz = BOOK
    c = BOOK_COVER
    p.box([sx / 2, sy / 2, c / 2], [0, 0, c / 2], name="cover_back")
    p.box([sx / 2, sy / 2, c / 2], [0, 0, sz - c / 2], name="cover_front")
    p.box([c / 2, sy / 2, sz / 2 - c], [-sx / 2 + c / 2, 0, sz / 2], name="spine")
    pages_hx = (sx - c - 0.003) / 2  # inset 3 mm from the fore edge
    p.box([pages_hx, sy / 2 - 0.003, sz / 2 - c], [-sx / 2 + c + pages_hx, 0, sz / 2],
          (0.95, 0.93, 0.86, 1.0), name="pages")


CATALOG.add_type(ObjectType(
    name="book", category="office", description="a hardcover book lying flat",
    size=BOOK, mass=0.3,
    colors={"red": (0.6, 0.12, 0.12, 1.0), "blue": (0.15, 0.22, 0.5, 1.0),
            "green": (0.15, 0.4, 0.25, 1.0), "brown": (0.45, 0.3, 0.18, 1.0)},
    build=_book, tags=frozenset({"flat", "office", "stackable", "support"}),
    annotations=Annotations(
        placements=(Placement("top", "on", (0, 0, BOOK[2]), (BOOK[0] / 2 - 0.015, BOOK[1] / 2 - 0.015)),),
    ),
))

# --- marker -------------------------------------------------------------------------------------
MARKER_R, MARKER_LEN, MARKER_CAP = 0.0095, 0.13, 0.045
_MARKER_END_R = MARKER_R + 0.001  # cap and end plug: the marker rests on these


def _marker(p: PartBuilder) -> None:
    z = _MARKER_END_R
    half = MARKER_LEN / 2
    p.cylinder(MARKER_R, half - 0.004, [0, 0, z], WHITE, name="barrel", quat=X_AXIS_QUAT)
    p.cylinder(_MARKER_END_R, MARKER_CAP / 2, [half - MARKER_CAP / 2, 0, z], name="cap", quat=X_AXIS_QUAT)
    p.cylinder(_MARKER_END_R, 0.004, [-half + 0.004, 0, z], name="plug", quat=X_AXIS_QUAT)
    p.box([0.014, 0.0015, 0.003], [half - 0.02, _MARKER_END_R + 0.0015, z], name="clip")
    # Flat feet under the cap and the end plug keep the round marker from rolling.
    for x, side in ((half - MARKER_CAP / 2, "cap"), (-half + 0.004, "plug")):
        p.box([0.004 if side == "plug" else MARKER_CAP / 2 - 0.002, 0.004, 0.001], [x, 0, 0.001],
              name=f"foot_{side}")


CATALOG.add_type(ObjectType(
    name="marker", category="office", description="a whiteboard marker",
    size=(MARKER_LEN, 2 * (_MARKER_END_R + 0.003), 2 * _MARKER_END_R), mass=0.015,
    colors={"black": (0.1, 0.1, 0.1, 1.0), "red": (0.8, 0.12, 0.12, 1.0),
            "blue": (0.15, 0.3, 0.8, 1.0), "green": (0.15, 0.6, 0.25, 1.0)},
    build=_marker, tags=frozenset({"graspable", "office", "pen"}),
    annotations=Annotations(grasps=grasp_pair("top", (0, 0, 0.02), 2 * MARKER_R, second=math.pi)),
))

# --- tape ---------------------------------------------------------------------------------------
TAPE_R_OUT, TAPE_R_IN, TAPE_H = 0.032, 0.019, 0.025


def _tape(p: PartBuilder) -> None:
    p.ring(TAPE_R_IN, TAPE_H, TAPE_R_OUT - TAPE_R_IN, segments=16)
    p.ring(TAPE_R_IN - 0.002, TAPE_H, 0.002, segments=16, rgba=(0.8, 0.68, 0.48, 1.0), name="core")


CATALOG.add_type(ObjectType(
    name="tape", category="office", description="a roll of masking tape",
    size=(2 * TAPE_R_OUT, 2 * TAPE_R_OUT, TAPE_H), mass=0.05,
    colors={"beige": (0.92, 0.86, 0.68, 1.0), "blue": (0.35, 0.55, 0.85, 1.0),
            "gray": (0.6, 0.62, 0.64, 1.0)},
    build=_tape, tags=frozenset({"graspable", "office", "round"}),
    annotations=Annotations(
        grasps=(*grasp_pair("top", (0, 0, 0.02), 2 * TAPE_R_OUT, second=math.pi),
                Grasp("rim", ((TAPE_R_OUT + TAPE_R_IN) / 2, 0, 0.02), yaw=HALF_PI,
                      width=TAPE_R_OUT - TAPE_R_IN)),
        stable_orientations=(StableOrientation("flat"),
                             StableOrientation("on_edge", (S2, S2, 0.0, 0.0))),
    ),
))

# --- display stand (pedestal) -------------------------------------------------------------------
PEDESTAL_BASE, PEDESTAL_TOP, PEDESTAL_H = 0.045, 0.04, 0.05
_PLATE = 0.008


def _object_stand(p: PartBuilder) -> None:
    b, t = PEDESTAL_BASE, PEDESTAL_TOP
    p.box([b, b, _PLATE / 2], [0, 0, _PLATE / 2], name="base")
    col = (PEDESTAL_H - 2 * _PLATE) / 2
    p.box([0.022, 0.022, col], [0, 0, _PLATE + col], name="column")
    p.box([t, t, _PLATE / 2], [0, 0, PEDESTAL_H - _PLATE / 2], name="top")


CATALOG.add_type(ObjectType(
    name="object_stand", category="office", description="a small square display pedestal",
    size=(2 * PEDESTAL_BASE, 2 * PEDESTAL_BASE, PEDESTAL_H), mass=0.2,
    colors={"white": (0.93, 0.93, 0.92, 1.0), "black": (0.16, 0.16, 0.17, 1.0),
            "wood": (0.62, 0.45, 0.28, 1.0)},
    build=_object_stand, tags=frozenset({"support", "stand", "office"}),
    annotations=Annotations(
        placements=(Placement("top", "on", (0, 0, PEDESTAL_H), (PEDESTAL_TOP - 0.005,) * 2),),
    ),
))

# --- dice ---------------------------------------------------------------------------------------
DICE = 0.04
_PIP = 0.0105
_PIPS = {
    1: [(0, 0)],
    2: [(-1, -1), (1, 1)],
    3: [(-1, -1), (0, 0), (1, 1)],
    4: [(-1, -1), (-1, 1), (1, -1), (1, 1)],
    5: [(-1, -1), (-1, 1), (0, 0), (1, -1), (1, 1)],
    6: [(-1, -1), (-1, 0), (-1, 1), (1, -1), (1, 0), (1, 1)],
}
_DICE_FACES = {"top": 1, "bottom": 6, "east": 2, "west": 5, "north": 3, "south": 4}


def _dice(p: PartBuilder) -> None:
    h = DICE / 2
    p.box([h, h, h], [0, 0, h], name="body")
    pip_rgba = WHITE if sum(p.rgba[:3]) < 1.8 else DARK
    for face, centre, u, v in _cube_faces(h):
        n = _DICE_FACES[face]
        inward = np.array([0.0, 0.0, h]) - centre
        inward /= np.linalg.norm(inward)
        for k, (a, b) in enumerate(_PIPS[n]):
            pos = centre + _PIP * (a * u + b * v) + 0.0028 * inward
            p.sphere(0.0035, pos.tolist(), pip_rgba, name=f"pip{n}_{k}", **VISUAL)


CATALOG.add_type(ObjectType(
    name="dice", category="toy", description="a large foam die",
    size=(DICE, DICE, DICE), mass=0.03,
    colors={"white": (0.95, 0.95, 0.93, 1.0), "red": (0.8, 0.12, 0.12, 1.0),
            "green": (0.2, 0.6, 0.3, 1.0)},
    build=_dice, tags=frozenset({"graspable", "toy", "stackable", "cube"}), scale_range=(0.95, 1.1),
    any_face=True,
    annotations=Annotations(
        grasps=grasp_pair("top", (0, 0, 0.025), DICE),
        stable_orientations=(
            StableOrientation("1_up"),
            StableOrientation("6_up", (0.0, 1.0, 0.0, 0.0)),
            StableOrientation("2_up", (S2, 0.0, -S2, 0.0)),
            StableOrientation("5_up", (S2, 0.0, S2, 0.0)),
            StableOrientation("3_up", (S2, S2, 0.0, 0.0)),
            StableOrientation("4_up", (S2, -S2, 0.0, 0.0)),
        ),
    ),
))

# --- toy car ------------------------------------------------------------------------------------
CAR = (0.1, 0.054, 0.05)
CAR_WHEEL_R = 0.012


def _toy_car(p: PartBuilder) -> None:
    r = CAR_WHEEL_R
    p.box([0.05, 0.022, 0.01], [0, 0, r + 0.01], name="chassis")
    p.box([0.026, 0.019, 0.009], [-0.006, 0, r + 0.029], name="cabin")
    p.box([0.0005, 0.015, 0.006], [0.0205, 0, r + 0.029], (0.6, 0.8, 0.95, 1.0), name="windshield",
          **VISUAL)
    for i, (sx, sy) in enumerate(((1, 1), (1, -1), (-1, 1), (-1, -1))):
        p.cylinder(r, 0.005, [sx * 0.032, sy * (CAR[1] / 2 - 0.005), r], DARK, name=f"wheel{i}",
                   quat=Y_AXIS_QUAT)


CATALOG.add_type(ObjectType(
    name="toy_car", category="toy", description="a small toy car",
    size=CAR, mass=0.08,
    colors={"red": (0.85, 0.12, 0.1, 1.0), "blue": (0.15, 0.35, 0.85, 1.0),
            "yellow": (0.95, 0.8, 0.1, 1.0), "green": (0.2, 0.65, 0.3, 1.0)},
    build=_toy_car, tags=frozenset({"graspable", "toy"}),
    annotations=Annotations(grasps=grasp_pair("top", (0, 0, 0.032), CAR[1], second=math.pi)),
))

# --- tennis ball --------------------------------------------------------------------------------
BALL_R = 0.0325


def _tennis_ball(p: PartBuilder) -> None:
    ball = p.sphere(BALL_R, [0, 0, BALL_R], name="ball")
    ball.condim = 6  # rolling friction: the ball slows down instead of rolling forever
    ball.friction = [p.friction, 0.005, 0.002]


CATALOG.add_type(ObjectType(
    name="tennis_ball", category="toy", description="a tennis ball",
    size=(2 * BALL_R, 2 * BALL_R, 2 * BALL_R), mass=0.058,
    colors={"yellow": (0.85, 0.92, 0.2, 1.0), "orange": (0.98, 0.6, 0.15, 1.0)},
    build=_tennis_ball, tags=frozenset({"graspable", "toy", "round", "rollable"}),
    scale_range=(0.95, 1.05),
    annotations=Annotations(grasps=grasp_pair("top", (0, 0, BALL_R), 2 * BALL_R)),
))

# --- Rubik's cube -------------------------------------------------------------------------------
RUBIK = 0.057
_RUBIK_COLORS = {
    "top": WHITE, "bottom": (0.98, 0.85, 0.1, 1.0), "east": (0.8, 0.1, 0.1, 1.0),
    "west": (0.98, 0.5, 0.1, 1.0), "north": (0.1, 0.3, 0.8, 1.0), "south": (0.1, 0.62, 0.25, 1.0),
}


def _rubik_cube(p: PartBuilder) -> None:
    h = RUBIK / 2
    p.box([h, h, h], [0, 0, h], name="body")
    cell = RUBIK / 3
    for face, centre, u, v in _cube_faces(h):
        normal = centre - np.array([0.0, 0.0, h])
        normal /= np.linalg.norm(normal)
        half = np.abs(u) * cell * 0.42 + np.abs(v) * cell * 0.42 + np.abs(normal) * 0.0004
        for i in (-1, 0, 1):
            for j in (-1, 0, 1):
                pos = centre + cell * (i * u + j * v) + 0.0003 * normal
                p.box(half.tolist(), pos.tolist(), _RUBIK_COLORS[face], name=f"{face}{i + 1}{j + 1}",
                      **VISUAL)


CATALOG.add_type(ObjectType(
    name="rubik_cube", category="toy", description="a Rubik's cube",
    size=(RUBIK, RUBIK, RUBIK), mass=0.09,
    colors={"black": (0.08, 0.08, 0.09, 1.0)},
    build=_rubik_cube, tags=frozenset({"graspable", "toy", "stackable", "cube", "colorful"}),
    scale_range=(0.95, 1.05), any_face=True,
    annotations=Annotations(grasps=grasp_pair("top", (0, 0, 0.035), RUBIK)),
))

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
