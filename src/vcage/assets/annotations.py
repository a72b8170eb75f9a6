"""Annotations carried by catalog object types, expressed in the object frame at scale 1.

The object frame has its origin at the centre of the object's resting face, z up.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

Vec3 = tuple[float, ...]  # (x, y, z)
HALF_PI = math.pi / 2
FOUR_SIDES = (0.0, HALF_PI, math.pi, -HALF_PI)  # angles of the four sides of a round object
RIM_DROP = 0.015  # rim grasps hold the wall this far below its top
S2 = math.sqrt(0.5)  # cos and sin of 45 degrees: quaternions of quarter turns


@dataclass(frozen=True)
class Grasp:
    """A top-down or angled grasp: the tool-centre point's position and the closing direction.

    ``yaw`` is the angle in the object's xy plane of the gripper's x axis (fingers close along the
    perpendicular direction); ``width`` is the object's extent between the fingers.
    ``tilt`` rotates the approach away from straight down (radians, about the gripper's y axis).
    """

    name: str
    pos: Vec3
    yaw: float = 0.0
    width: float = 0.04
    tilt: float = 0.0


def grasp_pair(name: str, pos: Vec3, width: float, yaw: float = 0.0,
               second: float = HALF_PI) -> tuple[Grasp, Grasp]:
    """Two top-down grasps at ``pos``: ``name`` at ``yaw`` and ``name_1`` at ``yaw + second``."""
    return (Grasp(name, pos, yaw=yaw, width=width), Grasp(f"{name}_1", pos, yaw=yaw + second, width=width))


def rim_grasps(radius: float, z: float, angles: tuple[float, ...], width: float,
               name: str = "rim") -> tuple[Grasp, ...]:
    """Grasps pinching a round wall at ``radius``, one per angle: the fingers close radially."""
    return tuple(
        Grasp(name if i == 0 else f"{name}_{i}", (radius * math.cos(a), radius * math.sin(a), z),
              yaw=a + HALF_PI, width=width)
        for i, a in enumerate(angles)
    )


@dataclass(frozen=True)
class Placement:
    """A region where other objects may rest (``on``) or be contained (``in``).

    ``pos`` is the centre of the region at the height of its supporting surface; ``half_size`` its
    half extents in x and y; ``wall_height`` the height of the containing walls for ``in``.
    ``joint`` names a slide joint along the object's x axis that the region rides on (a drawer's
    inside comes out with the drawer); ``pos`` is where it is at the joint's zero. ``slope`` is how
    far (radians) the supporting surface leans (a stand's ramp): what rests there leans with it.
    """

    name: str
    kind: str  # "on" | "in"
    pos: Vec3
    half_size: tuple[float, float]
    wall_height: float = 0.0
    joint: str | None = None
    slope: float = 0.0


@dataclass(frozen=True)
class FunctionalPoint:
    """A point with a function: a button to press, a switch side to toggle, a stamp face.

    ``joint`` names the object's joint that moves when the function is used (relative name), and
    ``travel`` how far it must move (metres or radians) to count as used. ``stroke`` is how far
    the point itself moves down over one full use (metres, object frame): the press depth a skill
    needs, whether the joint slides (a button) or turns (a lever, a rocker). For a ``handle`` (a
    drawer's), ``direction`` is the way the drawer comes out and ``stroke`` how far the skill
    that opens it pulls it (:mod:`vcage.skills.drawers`).
    """

    name: str
    kind: str  # "button" | "switch" | "lever" | "stamp" | "handle"
    pos: Vec3
    joint: str | None = None
    travel: float = 0.0
    stroke: float = 0.0
    direction: Vec3 = (0.0, 0.0, -1.0)


@dataclass(frozen=True)
class StableOrientation:
    """A resting orientation (quaternion w, x, y, z) in which the object stands still on a plane."""

    name: str
    quat: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Annotations:
    grasps: tuple[Grasp, ...] = ()
    placements: tuple[Placement, ...] = ()
    functional_points: tuple[FunctionalPoint, ...] = ()
    stable_orientations: tuple[StableOrientation, ...] = field(
        default_factory=lambda: (StableOrientation("upright"),)
    )
