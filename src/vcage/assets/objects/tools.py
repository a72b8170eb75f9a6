"""Tools and small appliances: a hammer, a rolling pin, a QR-code board and a desk fan.

Long things that would roll (the hammer's handle, the rolling pin) rest on flat feet. Objects
with a front (the board's code, the fan's outlet) mark it with a functional point whose
``direction`` is the outward normal, so a task can check which way they face.
"""

from __future__ import annotations

import math

from vcage.assets.annotations import HALF_PI, Annotations, FunctionalPoint, Placement, grasp_pair
from vcage.assets.catalog import CATALOG, ObjectType
from vcage.assets.parts import DARK, METAL, VISUAL, X_AXIS_QUAT, Y_AXIS_QUAT, PartBuilder

WOOD = (0.62, 0.45, 0.28, 1.0)
WHITE = (0.95, 0.95, 0.94, 1.0)

# --- hammer -------------------------------------------------------------------------------------
HAMMER_HEAD = (0.015, 0.045, 0.015)  # half extents: the head lies across the handle (along y)
HAMMER_HEAD_X = 0.085
HAMMER_HANDLE_R, HAMMER_HANDLE_HALF = 0.011, 0.08
HAMMER_HANDLE_X = -0.015
HAMMER_AXIS_Z = 0.015  # handle axis height: the head's centre


def _hammer(p: PartBuilder) -> None:
    hx, hy, hz = HAMMER_HEAD
    p.box([hx, hy, hz], [HAMMER_HEAD_X, 0, hz], METAL, name="head")
    p.capsule(HAMMER_HANDLE_R, HAMMER_HANDLE_HALF, [HAMMER_HANDLE_X, 0, HAMMER_AXIS_Z], name="handle",
              quat=X_AXIS_QUAT)
    # A foot under the handle's end: the hammer rests on it and on the head, level.
    end = HAMMER_HANDLE_X - HAMMER_HANDLE_HALF
    foot_h = HAMMER_AXIS_Z - HAMMER_HANDLE_R
    p.box([0.008, 0.007, foot_h / 2], [end + 0.01, 0, foot_h / 2], name="foot")


_HAMMER_X = HAMMER_HEAD_X + HAMMER_HEAD[0]
CATALOG.add_type(ObjectType(
    name="hammer", category="tool", description="a claw hammer lying on its side",
    size=(2 * _HAMMER_X, 2 * HAMMER_HEAD[1], 2 * HAMMER_HEAD[2]), mass=0.3,
    colors={"wood": WOOD, "red": (0.75, 0.15, 0.12, 1.0), "black": (0.15, 0.15, 0.16, 1.0),
            "yellow": (0.92, 0.75, 0.15, 1.0)},
    build=_hammer, tags=frozenset({"graspable", "tool"}), scale_range=(0.95, 1.05),
    annotations=Annotations(
        grasps=grasp_pair("handle", (0.0, 0, 0.02), 2 * HAMMER_HANDLE_R, second=math.pi),
        # the underside of the head: what strikes when the held hammer comes down
        functional_points=(FunctionalPoint("head", "striker", (HAMMER_HEAD_X, 0, 0)),),
    ),
))

# --- rolling pin --------------------------------------------------------------------------------
ROLLER_R, ROLLER_HALF = 0.024, 0.08  # the barrel
ROLLER_HANDLE_R, ROLLER_HANDLE_HALF = 0.012, 0.04
ROLLER_AXIS_Z = ROLLER_R + 0.002


def _roller(p: PartBuilder) -> None:
    p.cylinder(ROLLER_R, ROLLER_HALF, [0, 0, ROLLER_AXIS_Z], name="barrel", quat=X_AXIS_QUAT)
    foot_h = ROLLER_AXIS_Z - ROLLER_HANDLE_R
    for sgn, side in ((1, "a"), (-1, "b")):
        x = sgn * (ROLLER_HALF + ROLLER_HANDLE_HALF)
        p.cylinder(ROLLER_HANDLE_R, ROLLER_HANDLE_HALF, [x, 0, ROLLER_AXIS_Z], DARK,
                   name=f"handle_{side}", quat=X_AXIS_QUAT)
        p.box([0.012, 0.008, foot_h / 2], [sgn * (ROLLER_HALF + 0.05), 0, foot_h / 2], DARK,
              name=f"foot_{side}")


CATALOG.add_type(ObjectType(
    name="roller", category="kitchen", description="a wooden rolling pin with two handles",
    size=(2 * (ROLLER_HALF + 2 * ROLLER_HANDLE_HALF), 2 * ROLLER_R, ROLLER_AXIS_Z + ROLLER_R), mass=0.3,
    colors={"wood": WOOD, "pale": (0.85, 0.72, 0.52, 1.0), "white": (0.9, 0.9, 0.88, 1.0)},
    build=_roller, tags=frozenset({"graspable", "kitchen", "tool"}), scale_range=(0.95, 1.05),
    annotations=Annotations(grasps=grasp_pair("barrel", (0, 0, ROLLER_AXIS_Z + 0.006), 2 * ROLLER_R,
                                              second=math.pi)),
))

# --- QR-code board ------------------------------------------------------------------------------
QR_BASE = (0.03, 0.045, 0.005)  # half extents of the foot
QR_PLATE = (0.006, 0.045, 0.042)  # half extents of the upright board
_QR_CELLS = (  # a 5 x 5 pattern: 1 is a dark cell
    (1, 1, 0, 1, 1), (1, 0, 1, 0, 1), (0, 1, 1, 1, 0), (1, 0, 0, 1, 0), (1, 1, 0, 1, 1),
)


def _qr_board(p: PartBuilder) -> None:
    bx, by, bz = QR_BASE
    p.box([bx, by, bz], [0, 0, bz], DARK, name="foot")
    px, py, pz = QR_PLATE
    zc = 2 * bz + pz
    p.box([px, py, pz], [0, 0, zc], name="board")
    p.box([0.0004, py - 0.006, pz - 0.006], [px + 0.0004, 0, zc], WHITE, name="code", **VISUAL)
    cell = 2 * (py - 0.01) / 5
    for i, row in enumerate(_QR_CELLS):
        for j, dark in enumerate(row):
            if dark:
                p.box([0.0005, cell / 2, cell / 2],
                      [px + 0.0008, (j - 2) * cell, zc + (2 - i) * cell], DARK, name=f"cell{i}{j}",
                      **VISUAL)


_QR_H = 2 * QR_BASE[2] + 2 * QR_PLATE[2]
CATALOG.add_type(ObjectType(
    name="qr_board", category="office", description="a small standing board with a QR code on its front",
    size=(2 * QR_BASE[0], 2 * QR_BASE[1], _QR_H), mass=0.1,
    colors={"white": (0.9, 0.9, 0.88, 1.0), "blue": (0.2, 0.35, 0.7, 1.0),
            "green": (0.25, 0.55, 0.3, 1.0)},
    build=_qr_board, tags=frozenset({"graspable", "office"}), scale_range=(0.95, 1.05),
    annotations=Annotations(
        grasps=grasp_pair("board", (0, 0, _QR_H - 0.02), 2 * QR_PLATE[0], yaw=HALF_PI, second=math.pi),
        functional_points=(FunctionalPoint("code", "display", (QR_PLATE[0], 0, 2 * QR_BASE[2] + QR_PLATE[2]),
                                           direction=(1.0, 0.0, 0.0)),),
    ),
))

# --- desk fan -----------------------------------------------------------------------------------
FAN_BASE_R, FAN_BASE_H = 0.05, 0.014
FAN_POST_R = 0.01
FAN_HEAD_R, FAN_HEAD_HALF = 0.052, 0.018  # the head: a disc facing +x
FAN_HEAD_Z = 0.112


def _fan(p: PartBuilder) -> None:
    p.cylinder(FAN_BASE_R, FAN_BASE_H / 2, [0, 0, FAN_BASE_H / 2], name="base")
    post_top = FAN_HEAD_Z - FAN_HEAD_R + 0.01
    p.cylinder(FAN_POST_R, (post_top - FAN_BASE_H) / 2, [0, 0, (post_top + FAN_BASE_H) / 2], name="post")
    p.cylinder(FAN_HEAD_R, FAN_HEAD_HALF, [0, 0, FAN_HEAD_Z], name="head", quat=X_AXIS_QUAT)
    grille = (0.3, 0.3, 0.32, 1.0)
    p.cylinder(FAN_HEAD_R - 0.006, 0.0005, [FAN_HEAD_HALF + 0.0005, 0, FAN_HEAD_Z], grille,
               name="grille", quat=X_AXIS_QUAT, **VISUAL)
    p.cylinder(0.012, 0.001, [FAN_HEAD_HALF + 0.0015, 0, FAN_HEAD_Z], METAL, name="hub",
               quat=X_AXIS_QUAT, **VISUAL)


_FAN_H = FAN_HEAD_Z + FAN_HEAD_R
CATALOG.add_type(ObjectType(
    name="fan", category="device", description="a small desk fan with a round head",
    size=(2 * FAN_BASE_R, 2 * FAN_HEAD_R, round(_FAN_H, 4)), mass=0.35,
    colors={"white": (0.92, 0.92, 0.9, 1.0), "blue": (0.3, 0.5, 0.8, 1.0),
            "black": (0.15, 0.15, 0.16, 1.0), "pink": (0.9, 0.6, 0.7, 1.0)},
    build=_fan, tags=frozenset({"graspable", "device", "electronics"}), scale_range=(0.95, 1.05),
    annotations=Annotations(
        # pinching the head's front and back faces near its top: the palm clears the head
        grasps=grasp_pair("head", (0, 0, round(_FAN_H - 0.036, 4)), 2 * FAN_HEAD_HALF, yaw=HALF_PI,
                          second=math.pi),
        functional_points=(FunctionalPoint("outlet", "outlet", (FAN_HEAD_HALF, 0, FAN_HEAD_Z),
                                           direction=(1.0, 0.0, 0.0)),),
    ),
))

# --- cabinet with a drawer ----------------------------------------------------------------------
# A low cabinet whose drawer slides out towards -x (the robot, at yaw 0) on a damped slide joint
# (no spring: it stays where it is left). The drawer is a child body, so it never collides with the
# cabinet's own shell; its handle bar stands off the front far enough for a finger behind it, and
# high enough that the palm clears the cabinet's top. Everything is shifted by CAB_X0 so that the
# origin is the centre of the footprint (handle included).
CAB_HALF = (0.07, 0.11)  # shell half extents (x, y)
CAB_H, CAB_T = 0.065, 0.006  # shell height and plate thickness
DRAWER_FLOOR = 0.011  # top of the drawer's floor
DRAWER_WALL = 0.04
DRAWER_INNER = (0.055, 0.09)  # half extents of the drawer's inside
HANDLE_STANDOFF, HANDLE_Z = 0.055, 0.045
CAB_X0 = (0.004 + HANDLE_STANDOFF + 0.006) / 2  # half the handle's reach beyond the shell
DRAWER_RANGE = (-0.14, 0.0)  # pulled out (negative) to closed
DRAWER_TRAVEL = 0.08  # pulled out at least this far counts as open
DRAWER_PULL = 0.12  # how far the open_drawer skill pulls it out
_FRONT_X = -CAB_HALF[0] - 0.004 + CAB_X0  # the drawer front's outer face
_HANDLE_X = _FRONT_X - HANDLE_STANDOFF
DRAWER_CX = _FRONT_X + 0.008 + DRAWER_INNER[0]  # centre of the drawer's inside, shut


def _cabinet(p: PartBuilder) -> None:
    hx, hy = CAB_HALF
    x0, t = CAB_X0, CAB_T
    floor = p.box([hx, hy, t / 2], [x0, 0, t / 2], name="floor")
    floor.friction = [2.0 * p.friction, 0.005, 0.0001]  # rubber feet: pulling the drawer leaves it put
    p.box([hx, hy, t / 2], [x0, 0, CAB_H - t / 2], name="top")
    p.box([t / 2, hy, CAB_H / 2], [x0 + hx - t / 2, 0, CAB_H / 2], name="back")
    for sgn, side in ((1, "l"), (-1, "r")):
        p.box([hx, t / 2, CAB_H / 2], [x0, sgn * (hy - t / 2), CAB_H / 2], name=f"side_{side}")
    drawer = p.child("drawer", mass=0.05)
    joint = p.slide(drawer, "drawer", axis=(1, 0, 0), range_=DRAWER_RANGE, stiffness=0.0, damping=30.0)
    joint.armature = 0.01
    ix, iy = DRAWER_INNER
    cx = DRAWER_CX
    face = (0.9, 0.9, 0.88, 1.0)
    p.box([ix + 0.004, iy + 0.004, 0.002], [cx, 0, DRAWER_FLOOR - 0.002], face, name="drawer_floor",
          body=drawer)
    p.box([0.002, iy + 0.004, DRAWER_WALL / 2], [cx + ix + 0.002, 0, DRAWER_FLOOR + DRAWER_WALL / 2], face,
          name="drawer_back", body=drawer)
    for sgn, side in ((1, "l"), (-1, "r")):
        p.box([ix + 0.004, 0.002, DRAWER_WALL / 2], [cx, sgn * (iy + 0.002), DRAWER_FLOOR + DRAWER_WALL / 2],
              face, name=f"drawer_side_{side}", body=drawer)
    front_h = (CAB_H - 0.004) / 2
    p.box([0.004, hy, front_h], [_FRONT_X + 0.004, 0, 0.002 + front_h], name="drawer_front", body=drawer)
    for sgn, side in ((1, "l"), (-1, "r")):
        p.box([HANDLE_STANDOFF / 2, 0.004, 0.004], [_FRONT_X - HANDLE_STANDOFF / 2, sgn * 0.035, HANDLE_Z],
              METAL, name=f"handle_post_{side}", body=drawer)
    p.box([0.006, 0.045, 0.006], [_HANDLE_X, 0, HANDLE_Z], METAL, name="handle", body=drawer)


CATALOG.add_type(ObjectType(
    name="cabinet", category="furniture", description="a low cabinet with a sliding drawer and a bar handle",
    size=(round(2 * (CAB_HALF[0] + CAB_X0), 4), 2 * CAB_HALF[1], CAB_H), mass=1.0,
    colors={"wood": WOOD, "white": (0.9, 0.9, 0.88, 1.0), "gray": (0.5, 0.52, 0.55, 1.0)},
    build=_cabinet, tags=frozenset({"container", "pressable", "articulated", "furniture"}),
    scale_range=(1.0, 1.0),
    annotations=Annotations(
        # the drawer's inside (where it is while the drawer is shut; it comes out with the drawer)
        placements=(Placement("inside", "in", (round(DRAWER_CX, 4), 0, DRAWER_FLOOR), DRAWER_INNER,
                              DRAWER_WALL, joint="drawer"),),
        functional_points=(FunctionalPoint("handle", "handle", (round(_HANDLE_X, 4), 0, HANDLE_Z),
                                           joint="drawer", travel=DRAWER_TRAVEL, stroke=DRAWER_PULL,
                                           direction=(-1.0, 0.0, 0.0)),),
    ),
))

# --- mug rack -----------------------------------------------------------------------------------
# A post on a heavy base with one horizontal peg along -y: a mug hangs on it by its handle, the
# handle threaded over the peg's free end.
RACK_BASE = (0.07, 0.07, 0.006)  # half extents
RACK_POST = (0.0, 0.05, 0.01)  # x, y, radius of the post
RACK_H = 0.2
RACK_PEG_Z, RACK_PEG_R = 0.17, 0.005
RACK_PEG_END = -0.06  # y of the peg's free end


def _mug_rack(p: PartBuilder) -> None:
    bx, by, bz = RACK_BASE
    p.box([bx, by, bz], [0, 0, bz], name="base")
    x, y, r = RACK_POST
    p.cylinder(r, (RACK_H - 2 * bz) / 2, [x, y, bz + RACK_H / 2], name="post")
    half = (y - RACK_PEG_END) / 2
    p.cylinder(RACK_PEG_R, half, [x, (y + RACK_PEG_END) / 2, RACK_PEG_Z], METAL, name="peg",
               quat=Y_AXIS_QUAT)


CATALOG.add_type(ObjectType(
    name="mug_rack", category="kitchen",
    description="a mug rack: a post with a horizontal peg to hang a mug on",
    size=(2 * RACK_BASE[0], 2 * RACK_BASE[1], RACK_H), mass=0.9,
    colors={"wood": WOOD, "black": (0.15, 0.15, 0.16, 1.0), "white": (0.9, 0.9, 0.88, 1.0)},
    build=_mug_rack, tags=frozenset({"kitchen", "support"}), scale_range=(1.0, 1.0),
    annotations=Annotations(
        # the peg's free end; its direction is the peg's axis, the way a handle is threaded on
        functional_points=(FunctionalPoint("peg", "hook", (RACK_POST[0], RACK_PEG_END, RACK_PEG_Z),
                                           direction=(0.0, 1.0, 0.0)),),
    ),
))
