"""Annotations carried by catalog object types, expressed in the object frame at scale 1.

The object frame has its origin at the centre of the object's resting face, z up.
"""

from __future__ import annotations

from dataclasses import dataclass, field

Vec3 = tuple[float, ...]  # (x, y, z)


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


@dataclass(frozen=True)
class Placement:
    """A region where other objects may rest (``on``) or be contained (``in``).

    ``pos`` is the centre of the region at the height of its supporting surface; ``half_size`` its
    half extents in x and y; ``wall_height`` the height of the containing walls for ``in``.
    """

    name: str
    kind: str  # "on" | "in"
    pos: Vec3
    half_size: tuple[float, float]
    wall_height: float = 0.0


@dataclass(frozen=True)
class FunctionalPoint:
    """A point with a function: a button to press, a switch side to toggle, a stamp face.

    ``joint`` names the object's joint that moves when the function is used (relative name), and
    ``travel`` how far it must move (metres or radians) to count as used. ``stroke`` is how far
    the point itself moves down over one full use (metres, object frame): the press depth a skill
    needs, whether the joint slides (a button) or turns (a lever, a rocker).
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
