"""Food and kitchen items: cans, bottles, jars, fruit, bread, sponges, soap and a cereal box.

Round fruit sit on a small flat base so they stay where they are put instead of rolling.
"""

from __future__ import annotations

import math

from vcage.assets.annotations import HALF_PI, Annotations, Grasp, StableOrientation, grasp_pair
from vcage.assets.catalog import CATALOG, ObjectType
from vcage.assets.parts import METAL, VISUAL, X_AXIS_QUAT, PartBuilder
from vcage.geometry import mat_to_quat, rot_y, rot_z

# The hand's palm is ~47 mm above the grasp point, so grasps on tall things sit near their top.
PALM_CLEARANCE = 0.044
LYING = StableOrientation("lying", (math.sqrt(0.5), math.sqrt(0.5), 0.0, 0.0))


# --- can ----------------------------------------------------------------------------------------
CAN_R, CAN_H = 0.032, 0.122


def _can(p: PartBuilder) -> None:
    p.cylinder(CAN_R - 0.004, 0.002, [0, 0, 0.002], METAL, name="bottom")
    p.cylinder(CAN_R, (CAN_H - 0.008) / 2, [0, 0, CAN_H / 2], name="body")
    p.cylinder(CAN_R - 0.003, 0.002, [0, 0, CAN_H - 0.002], METAL, name="lid")
    p.box([0.006, 0.003, 0.0004], [0.008, 0, CAN_H + 0.0002], (0.6, 0.6, 0.62, 1.0), name="tab",
          **VISUAL)


CATALOG.add_type(ObjectType(
    name="can", category="food", description="a soda can",
    size=(2 * CAN_R, 2 * CAN_R, CAN_H), mass=0.2,
    colors={"red": (0.8, 0.1, 0.1, 1.0), "green": (0.15, 0.55, 0.25, 1.0),
            "blue": (0.15, 0.3, 0.75, 1.0), "silver": (0.75, 0.76, 0.78, 1.0)},
    build=_can, tags=frozenset({"graspable", "food", "kitchen", "drink", "cylindrical"}),
    annotations=Annotations(
        grasps=(*grasp_pair("side", (0, 0, 0.08), 2 * CAN_R),
                Grasp("side_2", (0, 0, 0.08), yaw=math.pi / 4, width=2 * CAN_R)),
        stable_orientations=(StableOrientation("upright"), LYING),
    ),
))

# --- bottle -------------------------------------------------------------------------------------
BOTTLE_R, BOTTLE_BODY_H = 0.03, 0.13
BOTTLE_NECK_R, BOTTLE_CAP_R, BOTTLE_CAP_H = 0.013, 0.015, 0.015
BOTTLE_H = 0.19


def _bottle(p: PartBuilder) -> None:
    p.cylinder(BOTTLE_R, BOTTLE_BODY_H / 2, [0, 0, BOTTLE_BODY_H / 2], name="body")
    p.cylinder(0.022, 0.0025, [0, 0, BOTTLE_BODY_H + 0.0025], name="shoulder")
    neck0, neck1 = BOTTLE_BODY_H + 0.005, BOTTLE_H - BOTTLE_CAP_H
    p.cylinder(BOTTLE_NECK_R, (neck1 - neck0) / 2, [0, 0, (neck0 + neck1) / 2], name="neck")
    p.cylinder(BOTTLE_CAP_R, BOTTLE_CAP_H / 2, [0, 0, BOTTLE_H - BOTTLE_CAP_H / 2], (0.95, 0.95, 0.95, 1.0),
               name="cap")
    p.cylinder(BOTTLE_R + 0.0005, 0.025, [0, 0, 0.07], (0.95, 0.95, 0.92, 1.0), name="label", **VISUAL)


CATALOG.add_type(ObjectType(
    name="bottle", category="kitchen", description="a plastic water bottle with a cap",
    size=(2 * BOTTLE_R, 2 * BOTTLE_R, BOTTLE_H), mass=0.25,
    colors={"blue": (0.45, 0.65, 0.9, 1.0), "green": (0.35, 0.7, 0.45, 1.0),
            "clear": (0.8, 0.87, 0.9, 1.0)},
    build=_bottle, tags=frozenset({"graspable", "kitchen", "drink", "cylindrical"}),
    annotations=Annotations(
        grasps=(*grasp_pair("neck", (0, 0, BOTTLE_H - BOTTLE_CAP_H), 2 * BOTTLE_CAP_R),
                *grasp_pair("body", (0, 0, BOTTLE_H - PALM_CLEARANCE), 2 * BOTTLE_R)),
        stable_orientations=(StableOrientation("upright"), LYING),
    ),
))

# --- jar ----------------------------------------------------------------------------------------
JAR_R, JAR_BODY_H, JAR_LID_H = 0.03, 0.085, 0.015


def _jar(p: PartBuilder) -> None:
    p.cylinder(JAR_R, JAR_BODY_H / 2, [0, 0, JAR_BODY_H / 2], name="body")
    p.cylinder(JAR_R + 0.001, JAR_LID_H / 2, [0, 0, JAR_BODY_H + JAR_LID_H / 2],
               (0.8, 0.7, 0.2, 1.0), name="lid")


CATALOG.add_type(ObjectType(
    name="jar", category="food", description="a glass jar of jam with a metal lid",
    size=(2 * JAR_R + 0.002, 2 * JAR_R + 0.002, JAR_BODY_H + JAR_LID_H), mass=0.25,
    colors={"strawberry": (0.7, 0.1, 0.15, 1.0), "apricot": (0.95, 0.6, 0.2, 1.0),
            "honey": (0.9, 0.7, 0.2, 1.0)},
    build=_jar, tags=frozenset({"graspable", "food", "kitchen", "cylindrical"}),
    annotations=Annotations(
        grasps=(*grasp_pair("body", (0, 0, 0.06), 2 * JAR_R),
                Grasp("lid", (0, 0, JAR_BODY_H + JAR_LID_H / 2), width=2 * JAR_R + 0.002)),
    ),
))


# --- apple and orange ---------------------------------------------------------------------------
def _fruit(p: PartBuilder, radius: float, base_r: float, base_h: float) -> float:
    """A sphere resting on a small flat base; returns the sphere centre height."""
    zc = radius + base_h / 2
    p.cylinder(base_r, base_h / 2, [0, 0, base_h / 2], name="base")
    p.sphere(radius, [0, 0, zc], name="body")
    return zc


APPLE_R, APPLE_H = 0.031, 0.072


def _apple(p: PartBuilder) -> None:
    zc = _fruit(p, APPLE_R, 0.016, 0.004)
    p.capsule(0.0018, 0.006, [0, 0, zc + APPLE_R + 0.004], (0.35, 0.22, 0.1, 1.0), name="stem")
    p.box([0.008, 0.004, 0.0008], [0.007, 0, zc + APPLE_R + 0.003], (0.25, 0.55, 0.2, 1.0),
          name="leaf", quat=mat_to_quat(rot_y(-0.4)).tolist(), **VISUAL)


CATALOG.add_type(ObjectType(
    name="apple", category="food", description="an apple",
    size=(2 * APPLE_R, 2 * APPLE_R, APPLE_H), mass=0.12,
    colors={"red": (0.78, 0.1, 0.1, 1.0), "green": (0.5, 0.78, 0.25, 1.0),
            "yellow": (0.92, 0.82, 0.3, 1.0)},
    build=_apple, tags=frozenset({"graspable", "food", "fruit"}),
    annotations=Annotations(grasps=grasp_pair("top", (0, 0, APPLE_R + 0.002), 2 * APPLE_R)),
))

ORANGE_R = 0.032


def _orange(p: PartBuilder) -> None:
    zc = _fruit(p, ORANGE_R, 0.014, 0.003)
    p.sphere(0.003, [0, 0, zc + ORANGE_R - 0.002], (0.4, 0.45, 0.15, 1.0), name="navel", **VISUAL)


CATALOG.add_type(ObjectType(
    name="orange", category="food", description="an orange",
    size=(2 * ORANGE_R, 2 * ORANGE_R, 2 * ORANGE_R + 0.003), mass=0.13,
    colors={"orange": (0.98, 0.55, 0.1, 1.0), "tangerine": (0.95, 0.45, 0.05, 1.0)},
    build=_orange, tags=frozenset({"graspable", "food", "fruit"}),
    annotations=Annotations(grasps=grasp_pair("top", (0, 0, ORANGE_R + 0.0015), 2 * ORANGE_R)),
))

# --- banana -------------------------------------------------------------------------------------
BANANA_ARC_R = 0.12  # radius of the banana's curve
BANANA_SPAN = 0.7  # half angle of the arc (rad)
BANANA_R = 0.017  # thickness radius of the middle
_BANANA_ANGLES = (-BANANA_SPAN, -BANANA_SPAN / 2, 0.0, BANANA_SPAN / 2, BANANA_SPAN)
_BANANA_SAG = BANANA_ARC_R * (1 - math.cos(BANANA_SPAN))


def _banana_point(theta: float) -> tuple[float, float]:
    return BANANA_ARC_R * math.sin(theta), BANANA_ARC_R * (1 - math.cos(theta)) - _BANANA_SAG / 2


def _banana(p: PartBuilder) -> None:
    pts = [_banana_point(a) for a in _BANANA_ANGLES]
    for i in range(len(pts) - 1):
        (x0, y0), (x1, y1) = pts[i], pts[i + 1]
        heading = math.atan2(y1 - y0, x1 - x0)
        quat = mat_to_quat(rot_z(heading) @ rot_y(HALF_PI)).tolist()
        r = BANANA_R if i in (1, 2) else BANANA_R * 0.85  # thinner ends, all resting on the table
        p.capsule(r, math.hypot(x1 - x0, y1 - y0) / 2, [(x0 + x1) / 2, (y0 + y1) / 2, r],
                  name=f"seg{i}", quat=quat)
    brown = (0.35, 0.25, 0.12, 1.0)
    (xa, ya), (xb, yb) = pts[-1], pts[-2]
    heading = math.atan2(ya - yb, xa - xb)
    quat = mat_to_quat(rot_z(heading) @ rot_y(HALF_PI)).tolist()
    stem_xy = [xa + 0.01 * math.cos(heading), ya + 0.01 * math.sin(heading)]
    p.capsule(0.005, 0.008, [*stem_xy, BANANA_R], brown, name="stem", quat=quat)
    p.sphere(0.005, [pts[0][0] - 0.006, pts[0][1], 0.85 * BANANA_R], brown, name="tip", **VISUAL)


_BANANA_X = BANANA_ARC_R * math.sin(BANANA_SPAN) + 0.03
CATALOG.add_type(ObjectType(
    name="banana", category="food", description="a ripe banana",
    size=(2 * _BANANA_X, round(_BANANA_SAG + 2 * BANANA_R + 0.004, 4), 2 * BANANA_R), mass=0.12,
    colors={"yellow": (0.96, 0.85, 0.25, 1.0), "green": (0.65, 0.78, 0.25, 1.0)},
    build=_banana, tags=frozenset({"graspable", "food", "fruit"}),
    annotations=Annotations(
        grasps=grasp_pair("middle", (0, _banana_point(0.0)[1], 0.02), 2 * BANANA_R, second=math.pi),
    ),
))

# --- bread --------------------------------------------------------------------------------------
BREAD = (0.14, 0.062, 0.068)  # loaf length, width, height: fits a basket at any scale


def _bread(p: PartBuilder) -> None:
    lx, ly, lz = BREAD
    cap_r = ly / 2
    p.box([lx / 2, ly / 2, (lz - cap_r) / 2], [0, 0, (lz - cap_r) / 2], name="loaf")
    p.capsule(cap_r, lx / 2 - cap_r, [0, 0, lz - cap_r], name="crust", quat=X_AXIS_QUAT)
    score = tuple(0.8 * c for c in p.rgba[:3]) + (1.0,)
    for i, x in enumerate((-0.03, 0.0, 0.03)):
        p.box([0.004, ly * 0.3, 0.001], [x, 0, lz - 0.0005], score, name=f"score{i}",
              quat=mat_to_quat(rot_z(0.5)).tolist(), **VISUAL)


CATALOG.add_type(ObjectType(
    name="bread", category="food", description="a small loaf of bread",
    size=BREAD, mass=0.15,
    colors={"wheat": (0.82, 0.6, 0.33, 1.0), "rye": (0.48, 0.32, 0.18, 1.0),
            "white": (0.93, 0.82, 0.6, 1.0)},
    build=_bread, tags=frozenset({"graspable", "food", "soft"}),
    annotations=Annotations(
        grasps=(*grasp_pair("top", (0, 0, 0.045), BREAD[1], second=math.pi),
                *grasp_pair("top_end", (0.035, 0, 0.045), BREAD[1], second=math.pi)),
    ),
))

# --- sponge -------------------------------------------------------------------------------------
SPONGE = (0.09, 0.06, 0.032)
SPONGE_SCRUB = 0.007


def _sponge(p: PartBuilder) -> None:
    sx, sy, sz = SPONGE
    foam = sz - SPONGE_SCRUB
    p.box([sx / 2, sy / 2, foam / 2], [0, 0, foam / 2], name="foam")
    p.box([sx / 2, sy / 2, SPONGE_SCRUB / 2], [0, 0, foam + SPONGE_SCRUB / 2], (0.15, 0.45, 0.2, 1.0),
          name="scrub")


CATALOG.add_type(ObjectType(
    name="sponge", category="kitchen", description="a kitchen sponge with a scrubbing side",
    size=SPONGE, mass=0.02,
    colors={"yellow": (0.97, 0.85, 0.3, 1.0), "pink": (0.95, 0.6, 0.7, 1.0),
            "blue": (0.45, 0.65, 0.9, 1.0)},
    build=_sponge, tags=frozenset({"graspable", "kitchen", "soft", "stackable"}),
    annotations=Annotations(grasps=grasp_pair("top", (0, 0, 0.022), SPONGE[1], second=math.pi)),
))

# --- soap ---------------------------------------------------------------------------------------
SOAP = (0.085, 0.056, 0.03)


def _soap(p: PartBuilder) -> None:
    sx, sy, sz = SOAP
    p.box([sx / 2, sy / 2, sz * 0.35], [0, 0, sz * 0.35], name="bar")
    p.box([sx / 2 - 0.004, sy / 2 - 0.004, sz * 0.15], [0, 0, sz * 0.85], name="top")


CATALOG.add_type(ObjectType(
    name="soap", category="kitchen", description="a bar of soap",
    size=SOAP, mass=0.1,
    colors={"white": (0.95, 0.95, 0.93, 1.0), "lavender": (0.75, 0.65, 0.88, 1.0),
            "green": (0.6, 0.85, 0.6, 1.0)},
    build=_soap, tags=frozenset({"graspable", "kitchen", "stackable"}),
    annotations=Annotations(grasps=grasp_pair("top", (0, 0, 0.02), SOAP[1], second=math.pi)),
))

# --- cereal box ---------------------------------------------------------------------------------
CEREAL = (0.05, 0.14, 0.2)


def _cereal_box(p: PartBuilder) -> None:
    sx, sy, sz = CEREAL
    p.box([sx / 2, sy / 2, sz / 2], [0, 0, sz / 2], name="box")
    for sgn, side in ((1, "front"), (-1, "back")):
        p.box([0.0005, sy * 0.35, sz * 0.2], [sgn * (sx / 2 + 0.0005), 0, sz * 0.6],
              (0.97, 0.9, 0.3, 1.0), name=f"logo_{side}", **VISUAL)
        p.cylinder(0.02, 0.0005, [sgn * (sx / 2 + 0.0005), 0.02, sz * 0.28], (0.9, 0.5, 0.15, 1.0),
                   name=f"bowl_art_{side}", quat=X_AXIS_QUAT, **VISUAL)


CATALOG.add_type(ObjectType(
    name="cereal_box", category="food", description="a small box of breakfast cereal",
    size=CEREAL, mass=0.2,
    colors={"red": (0.75, 0.15, 0.15, 1.0), "blue": (0.2, 0.35, 0.75, 1.0),
            "green": (0.25, 0.6, 0.3, 1.0)},
    build=_cereal_box, tags=frozenset({"graspable", "food", "kitchen"}),
    annotations=Annotations(grasps=grasp_pair("side", (0, 0, CEREAL[2] - PALM_CLEARANCE), CEREAL[0],
                                              yaw=HALF_PI, second=math.pi)),
))
