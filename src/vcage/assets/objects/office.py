"""Desk things: a computer mouse and pad, a phone and its stand, a playing card, a book, a marker,
tape and a display stand.
"""

from __future__ import annotations

import math

import numpy as np

from vcage.assets.annotations import (
    HALF_PI,
    S2,
    Annotations,
    Grasp,
    Placement,
    StableOrientation,
    grasp_pair,
)
from vcage.assets.catalog import CATALOG, ObjectType
from vcage.assets.parts import DARK, VISUAL, WHITE, X_AXIS_QUAT, Y_AXIS_QUAT, PartBuilder
from vcage.geometry import mat_to_quat, rot_y

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
