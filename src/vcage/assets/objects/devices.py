"""Articulated and functional objects: a desk bell, an alarm clock, a stapler, a rocker switch,
and a stamp (seal) with its ink mat.

Moving parts are child bodies with a named joint (``<instance>/<joint>``) whose spring reference
(``qpos_spring``) is the rest value. Buttons are stiff-sprung slide joints resting at their upper
limit; the stapler arm is held open by a hinge spring. The rocker switch is bistable: its centre of
mass lies above the pivot, so it rests against either limit and a press on the raised side tips it
over (it does not spring back). Hinge angles honour the spec's angle unit (MjSpec defaults to
degrees); PartBuilder.hinge converts.
"""

from __future__ import annotations

import math

import numpy as np

from vcage.assets.annotations import HALF_PI, Annotations, FunctionalPoint, Grasp, Placement, grasp_pair
from vcage.assets.catalog import CATALOG, ObjectType
from vcage.assets.parts import DARK, METAL, RGBA, VISUAL, X_AXIS_QUAT, Y_AXIS_QUAT, PartBuilder
from vcage.geometry import mat_to_quat, rot_y

# Push buttons rest at their upper limit, which is also the spring's reference (so the joint's
# ``qpos_spring`` is its rest value). The spring is stiff enough that the light button sags only
# 0.1 mm under its own weight, and a press of about 2 N moves it the annotated travel.
BUTTON_K = 500.0  # N/m
BUTTON_MASS = 0.005  # kg
BUTTON_RANGE = (-0.009, 0.0)  # room for a press that overshoots the travel
BUTTON_TRAVEL = 0.004


def _button(p: PartBuilder, pos: tuple[float, float, float], radius: float, height: float,
            rgba: RGBA) -> None:
    """A push button whose body origin is at ``pos`` (the base of its cap) moving along z."""
    body = p.child("button", pos=pos, mass=BUTTON_MASS)
    body.ipos = [0.0, 0.0, height / 2 * p.scale]
    joint = p.slide(body, "button", axis=(0, 0, 1), range_=BUTTON_RANGE, stiffness=BUTTON_K,
                    damping=2.0, springref=0.0)
    joint.armature = 0.005
    p.cylinder(radius, height / 2, [0, 0, height / 2], rgba, name="button_cap", body=body)
    # A plunger reaching down into the housing keeps the button visibly seated when pressed.
    p.cylinder(radius * 0.6, 0.004, [0, 0, -0.004], rgba, name="button_stem", body=body)


# --- desk bell ----------------------------------------------------------------------------------
BELL_BASE_R, BELL_BASE_H = 0.045, 0.012
BELL_DOME_R = 0.038
BELL_BUTTON_Z = BELL_BASE_H + BELL_DOME_R  # top of the dome: the button sits here
BELL_BUTTON_H = 0.01


def _bell(p: PartBuilder) -> None:
    p.cylinder(BELL_BASE_R, BELL_BASE_H / 2, [0, 0, BELL_BASE_H / 2], (0.25, 0.15, 0.08, 1.0),
               name="base")
    # The dome is drawn as a sphere half hidden in the base; it collides through a cylinder inside.
    p.sphere(BELL_DOME_R, [0, 0, BELL_BASE_H], name="dome", **VISUAL)
    p.cylinder(0.025, 0.014, [0, 0, BELL_BASE_H + 0.014], name="dome_core", rgba=p.rgba)
    p.cylinder(0.005, 0.004, [0, 0, BELL_BUTTON_Z - 0.003], METAL, name="button_guide")
    _button(p, (0, 0, BELL_BUTTON_Z), 0.008, BELL_BUTTON_H, METAL)


_BELL_TOP = round(BELL_BUTTON_Z + BELL_BUTTON_H, 4)
CATALOG.add_type(ObjectType(
    name="bell", category="device", description="a desk service bell with a push button on top",
    size=(2 * BELL_BASE_R, 2 * BELL_BASE_R, _BELL_TOP), mass=0.3,
    colors={"gold": (0.85, 0.68, 0.25, 1.0), "silver": (0.8, 0.8, 0.83, 1.0),
            "red": (0.75, 0.15, 0.12, 1.0)},
    build=_bell, tags=frozenset({"pressable", "device", "articulated"}), scale_range=(0.95, 1.05),
    annotations=Annotations(
        functional_points=(FunctionalPoint("button", "button", (0, 0, _BELL_TOP), joint="button",
                                           travel=BUTTON_TRAVEL, stroke=BUTTON_TRAVEL),),
    ),
))

# --- alarm clock --------------------------------------------------------------------------------
CLOCK_HALF = (0.025, 0.05, 0.04)  # half extents of the housing (depth x, width y, height z)
CLOCK_FEET = 0.004
CLOCK_TOP = CLOCK_FEET + 2 * CLOCK_HALF[2]
CLOCK_BUTTON_H = 0.008


def _alarm_clock(p: PartBuilder) -> None:
    hx, hy, hz = CLOCK_HALF
    for sgn, side in ((1, "l"), (-1, "r")):
        p.box([hx * 0.8, 0.008, CLOCK_FEET / 2], [0, sgn * (hy - 0.012), CLOCK_FEET / 2], DARK,
              name=f"foot_{side}")
        p.sphere(0.011, [0, sgn * 0.032, CLOCK_TOP - 0.003], METAL, name=f"bell_{side}", **VISUAL)
    p.box([hx, hy, hz], [0, 0, CLOCK_FEET + hz], name="housing")
    zc = CLOCK_FEET + hz
    p.cylinder(0.034, 0.001, [hx + 0.001, 0, zc], (0.96, 0.96, 0.92, 1.0), name="face",
               quat=X_AXIS_QUAT, **VISUAL)
    p.box([0.0006, 0.0015, 0.02], [hx + 0.0025, 0, zc + 0.017], DARK, name="hand_min", **VISUAL)
    p.box([0.0006, 0.012, 0.0018], [hx + 0.0025, 0.01, zc], DARK, name="hand_hour", **VISUAL)
    p.cylinder(0.005, 0.002, [0, 0, CLOCK_TOP - 0.002], METAL, name="button_guide")
    _button(p, (0, 0, CLOCK_TOP), 0.01, CLOCK_BUTTON_H, (0.85, 0.2, 0.15, 1.0))


_CLOCK_H = round(CLOCK_TOP + CLOCK_BUTTON_H, 4)
CATALOG.add_type(ObjectType(
    name="alarm_clock", category="device", description="an alarm clock with a button on top",
    size=(2 * CLOCK_HALF[0] + 0.006, 2 * CLOCK_HALF[1], _CLOCK_H), mass=0.25,
    colors={"white": (0.92, 0.92, 0.9, 1.0), "blue": (0.25, 0.45, 0.75, 1.0),
            "green": (0.35, 0.65, 0.4, 1.0), "pink": (0.9, 0.55, 0.65, 1.0)},
    build=_alarm_clock, tags=frozenset({"pressable", "device", "articulated", "graspable"}),
    annotations=Annotations(
        # High enough that the palm clears the button (the palm is ~47 mm above the grasp point).
        grasps=(Grasp("side", (0, 0, _CLOCK_H - 0.042), yaw=HALF_PI, width=2 * CLOCK_HALF[0]),
                Grasp("side_1", (0, 0, _CLOCK_H - 0.042), yaw=-HALF_PI, width=2 * CLOCK_HALF[0])),
        functional_points=(FunctionalPoint("button", "button", (0, 0, _CLOCK_H), joint="button",
                                           travel=BUTTON_TRAVEL, stroke=BUTTON_TRAVEL),),
    ),
))

# --- stapler ------------------------------------------------------------------------------------
STAPLER_BASE = (0.075, 0.018, 0.0075)  # half extents of the base
STAPLER_HINGE = (-0.062, 0.0, 0.03)
STAPLER_ARM_LEN = 0.135
STAPLER_OPEN = 0.25  # rad: the arm's front rises this much at rest
STAPLER_K = 1.5  # N m / rad about the open pose: the arm droops ~0.013 rad under its weight


def _vec3(v: np.ndarray) -> tuple[float, float, float]:
    return round(float(v[0]), 4), round(float(v[1]), 4), round(float(v[2]), 4)


def _stapler_point(x: float, z: float, angle: float = -STAPLER_OPEN) -> np.ndarray:
    """A point of the arm (arm frame: x forward from the hinge) in the object frame."""
    return np.asarray(STAPLER_HINGE) + rot_y(angle) @ np.array([x, 0.0, z])


def _stapler(p: PartBuilder) -> None:
    bx, by, bz = STAPLER_BASE
    p.box([bx, by, bz], [0, 0, bz], DARK, name="base")
    p.box([0.02, by * 0.8, 0.0015], [bx - 0.025, 0, 2 * bz + 0.0015], METAL, name="anvil")
    hx, _, hz = STAPLER_HINGE
    p.box([0.01, by * 0.9, (hz - 2 * bz) / 2 + 0.004], [hx, 0, (hz + 2 * bz) / 2], DARK, name="post")
    # The arm is built open (front up); the joint's reference makes that pose read -STAPLER_OPEN,
    # which is also the spring's reference. 0 is closed (arm horizontal).
    arm = p.child("arm", pos=STAPLER_HINGE, mass=0.03)
    arm.quat = mat_to_quat(rot_y(-STAPLER_OPEN)).tolist()
    arm.ipos = [STAPLER_ARM_LEN / 2 * p.scale, 0.0, 0.004 * p.scale]
    joint = p.hinge(arm, "arm", axis=(0, 1, 0),
                    range_=(-STAPLER_OPEN - 0.05, 0.0), stiffness=STAPLER_K, damping=0.02,
                    springref=-STAPLER_OPEN, ref=-STAPLER_OPEN)
    joint.armature = 1e-4
    length = STAPLER_ARM_LEN
    p.box([length / 2, 0.016, 0.01], [length / 2, 0, 0.004], name="arm_top", body=arm)
    p.box([0.012, 0.017, 0.004], [length - 0.012, 0, 0.011], DARK, name="arm_tip", body=arm)
    p.cylinder(0.006, 0.018, [0, 0, 0], METAL, name="hinge_pin", quat=Y_AXIS_QUAT, body=arm)


_STAPLER_PRESS = _vec3(_stapler_point(STAPLER_ARM_LEN - 0.015, 0.015))
# the press point's drop from the open arm to the closed one
_STAPLER_STROKE = round(float(_STAPLER_PRESS[2] - _stapler_point(STAPLER_ARM_LEN - 0.015, 0.015, 0.0)[2]), 4)
_STAPLER_TOP = float(_stapler_point(STAPLER_ARM_LEN, 0.015)[2])
CATALOG.add_type(ObjectType(
    name="stapler", category="device", description="a desk stapler with a spring-loaded arm",
    size=(2 * STAPLER_BASE[0] + 0.004, 0.04, round(_STAPLER_TOP + 0.002, 4)), mass=0.2,
    colors={"red": (0.78, 0.14, 0.12, 1.0), "black": (0.2, 0.2, 0.22, 1.0),
            "blue": (0.2, 0.35, 0.7, 1.0)},
    build=_stapler, tags=frozenset({"pressable", "device", "articulated", "office", "graspable"}),
    annotations=Annotations(
        grasps=grasp_pair("body", (0.0, 0.0, 0.04), 0.036, second=math.pi),
        functional_points=(FunctionalPoint("press", "lever", _STAPLER_PRESS, joint="arm",
                                           travel=0.15, stroke=_STAPLER_STROKE),),
    ),
))

# --- rocker switch ------------------------------------------------------------------------------
SWITCH_BASE = (0.04, 0.03, 0.011)  # half extents of the base box
SWITCH_PIVOT_Z = 2 * SWITCH_BASE[2] + 0.004
SWITCH_ROCKER = (0.022, 0.018, 0.005)  # half extents of the rocker
SWITCH_THROW = 0.25  # rad to either side


def _switch_point(x: float, angle: float = -SWITCH_THROW) -> np.ndarray:
    """A point on the rocker's top face (rocker frame x) in the object frame."""
    return np.array([0.0, 0.0, SWITCH_PIVOT_Z]) + rot_y(angle) @ np.array([x, 0.0, 2 * SWITCH_ROCKER[2]])


def _switch(p: PartBuilder) -> None:
    bx, by, bz = SWITCH_BASE
    p.box([bx, by, bz], [0, 0, bz], (0.88, 0.88, 0.86, 1.0), name="base")
    p.box([SWITCH_ROCKER[0] + 0.004, SWITCH_ROCKER[1] + 0.004, 0.002], [0, 0, 2 * bz + 0.002],
          DARK, name="bezel")
    # Built tilted to the "off" side; the joint's reference makes that pose read -SWITCH_THROW.
    rocker = p.child("toggle", pos=(0, 0, SWITCH_PIVOT_Z), mass=0.03)
    rocker.quat = mat_to_quat(rot_y(-SWITCH_THROW)).tolist()
    rocker.ipos = [0.0, 0.0, 0.02 * p.scale]  # centre of mass above the pivot: bistable
    # No spring (stiffness 0); its reference only marks the rest ("off") side as qpos_spring.
    joint = p.hinge(rocker, "toggle", axis=(0, 1, 0),
                    range_=(-SWITCH_THROW, SWITCH_THROW), damping=0.01, springref=-SWITCH_THROW,
                    ref=-SWITCH_THROW)
    joint.armature = 1e-4
    rx, ry, rz = SWITCH_ROCKER
    p.box([rx, ry, rz], [0, 0, rz], name="rocker", body=rocker)
    p.box([0.0015, ry * 0.6, 0.0004], [rx * 0.55, 0, 2 * rz + 0.0004], (0.95, 0.95, 0.95, 1.0),
          name="mark_on", body=rocker, **VISUAL)


_SWITCH_ON = _vec3(_switch_point(SWITCH_ROCKER[0] * 0.7))
_SWITCH_OFF = _vec3(_switch_point(-SWITCH_ROCKER[0] * 0.7, SWITCH_THROW))
# the "on" point's drop from the off pose to the fully thrown one (past vertical it tips over)
_SWITCH_STROKE = round(float(_SWITCH_ON[2] - _switch_point(SWITCH_ROCKER[0] * 0.7, SWITCH_THROW)[2]), 4)
_SWITCH_TOP = float(_switch_point(SWITCH_ROCKER[0])[2])
CATALOG.add_type(ObjectType(
    name="switch", category="device", description="a rocker switch on a small base",
    size=(2 * SWITCH_BASE[0], 2 * SWITCH_BASE[1], round(_SWITCH_TOP + 0.002, 4)), mass=0.15,
    colors={"red": (0.8, 0.15, 0.12, 1.0), "black": (0.15, 0.15, 0.16, 1.0),
            "green": (0.2, 0.65, 0.3, 1.0)},
    build=_switch, tags=frozenset({"pressable", "device", "articulated", "toggle"}),
    annotations=Annotations(
        functional_points=(
            FunctionalPoint("on", "switch", _SWITCH_ON, joint="toggle", travel=0.3,
                            stroke=_SWITCH_STROKE),
            FunctionalPoint("off", "switch", _SWITCH_OFF, joint="toggle", travel=0.3,
                            stroke=_SWITCH_STROKE),
        ),
    ),
))

# --- seal (stamp) -------------------------------------------------------------------------------
SEAL_BASE = (0.025, 0.025, 0.01)  # half extents of the square block
SEAL_RUBBER = 0.003
SEAL_HANDLE_R, SEAL_HANDLE_H = 0.012, 0.06
SEAL_KNOB_R = 0.016
_SEAL_HANDLE_Z0 = SEAL_RUBBER + 2 * SEAL_BASE[2]
_SEAL_TOP = _SEAL_HANDLE_Z0 + SEAL_HANDLE_H + SEAL_KNOB_R * 1.5


def _seal(p: PartBuilder) -> None:
    bx, by, bz = SEAL_BASE
    p.box([bx - 0.002, by - 0.002, SEAL_RUBBER / 2], [0, 0, SEAL_RUBBER / 2], p.rgba, name="face")
    p.box([bx, by, bz], [0, 0, SEAL_RUBBER + bz], (0.55, 0.38, 0.22, 1.0), name="block")
    wood = (0.45, 0.3, 0.17, 1.0)
    p.cylinder(SEAL_HANDLE_R, SEAL_HANDLE_H / 2, [0, 0, _SEAL_HANDLE_Z0 + SEAL_HANDLE_H / 2], wood,
               name="handle")
    p.sphere(SEAL_KNOB_R, [0, 0, _SEAL_TOP - SEAL_KNOB_R], wood, name="knob")


_SEAL_GRASP_Z = _SEAL_HANDLE_Z0 + 0.042  # finger tips clear the block, the palm the knob
CATALOG.add_type(ObjectType(
    name="seal", category="office", description="a rubber stamp with a wooden handle",
    size=(2 * SEAL_BASE[0], 2 * SEAL_BASE[1], round(_SEAL_TOP, 4)), mass=0.12,
    colors={"red": (0.8, 0.12, 0.12, 1.0), "blue": (0.15, 0.25, 0.75, 1.0),
            "black": (0.1, 0.1, 0.1, 1.0)},
    build=_seal, tags=frozenset({"graspable", "office", "tool", "stamp"}),
    annotations=Annotations(
        grasps=grasp_pair("handle", (0, 0, _SEAL_GRASP_Z), 2 * SEAL_HANDLE_R),
        functional_points=(FunctionalPoint("face", "stamp", (0, 0, 0)),),
    ),
))

# --- stamp mat ----------------------------------------------------------------------------------
MAT_HALF = (0.06, 0.045)
MAT_H = 0.006


def _stamp_mat(p: PartBuilder) -> None:
    p.box([MAT_HALF[0], MAT_HALF[1], MAT_H / 2 - 0.001], [0, 0, MAT_H / 2 - 0.001], DARK,
          name="case")
    p.box([MAT_HALF[0] - 0.006, MAT_HALF[1] - 0.006, 0.001], [0, 0, MAT_H - 0.001], name="ink")


CATALOG.add_type(ObjectType(
    name="stamp_mat", category="office", description="a flat inked stamp pad",
    size=(2 * MAT_HALF[0], 2 * MAT_HALF[1], MAT_H), mass=0.06,
    colors={"red": (0.8, 0.12, 0.12, 1.0), "blue": (0.15, 0.25, 0.75, 1.0),
            "black": (0.1, 0.1, 0.1, 1.0), "green": (0.15, 0.55, 0.25, 1.0)},
    build=_stamp_mat, tags=frozenset({"flat", "office", "support"}),
    annotations=Annotations(
        placements=(Placement("top", "on", (0, 0, MAT_H), (MAT_HALF[0] - 0.01, MAT_HALF[1] - 0.01)),),
    ),
))
