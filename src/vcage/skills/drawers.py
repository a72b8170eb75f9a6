"""Sliding a drawer by its handle: the skills ``open_drawer`` and ``close_drawer``.

A drawer is a functional point of kind ``handle`` on a slide joint (:mod:`vcage.assets.annotations`):
``direction`` is the way the drawer comes out (object frame), ``travel`` how far out counts as open
and ``stroke`` how far out :func:`open_drawer` pulls it. The catalog's drawers slide along their
object's x axis, out towards negative joint values.

Both skills come down on the handle with the hand ajar (the finger behind the handle must fit in
front of the drawer), close it, slide the handle in a straight line, let go and move up: one
plan, open loop from the state they are planned in, like ``pick_and_place``.
"""

from __future__ import annotations

import math

import numpy as np

from vcage.assets.annotations import FunctionalPoint
from vcage.assets.catalog import CATALOG
from vcage.errors import SkillError
from vcage.geometry import yaw_of
from vcage.sim.world import World
from vcage.skills.base import CLOSED, OPEN, SKILLS, SLOW_SPEED, Skills
from vcage.skills.motion import MotionPlan, Waypoint

ABOVE = 0.08  # the hand comes down onto the handle from this far above it
AJAR = 0.4  # gripper opening around the handle
SLIDE_SPEED = 0.08  # metres per second while the drawer moves
PAST_SHUT = 0.005  # closing pushes this far past shut: the joint's stop holds the drawer there


def handle_of(world: World, obj: str, point: str | None = None) -> FunctionalPoint:
    """``obj``'s drawer handle (its functional point ``point``); SkillError if it has none."""
    otype = CATALOG.get(world.object(obj).type_name)
    fp = otype.drawer_handle(point)
    if fp is None:
        raise SkillError(f"{obj!r} ({otype.name}) has no drawer handle"
                         + (f" named {point!r}" if point else "") + "; objects with a drawer have one")
    return fp


def opening(world: World, obj: str, point: str | None = None) -> float:
    """How far ``obj``'s drawer is out now (metres; 0 shut)."""
    return -world.joint_value(f"{obj}/{handle_of(world, obj, point).joint}")


def slid(world: World, obj: str, joint: str | None) -> np.ndarray:
    """Where what rides on ``obj``'s slide joint ``joint`` (along the object's x axis) is now,
    relative to where it is at the joint's zero (object frame, metres); zero without a joint."""
    return np.array([world.joint_value(f"{obj}/{joint}") if joint else 0.0, 0.0, 0.0])


def handle_pos(world: World, obj: str, point: str | None = None) -> np.ndarray:
    """World position of ``obj``'s drawer handle now (it moves with the drawer)."""
    inst = world.object(obj)
    fp = handle_of(world, obj, point)
    local = np.asarray(fp.pos, float) * inst.scale + slid(world, obj, fp.joint)
    return world.object_pos(obj) + world.object_mat(obj) @ local


def slide(s: Skills, obj: str, to: float, point: str | None = None, name: str = "slide") -> MotionPlan:
    """Take ``obj``'s drawer handle, slide the drawer until it is ``to`` metres out, let go and move
    up (a little past 0 shuts it; past the joint's range its stop holds the drawer)."""
    world = s.world
    fp = handle_of(world, obj, point)
    handle = handle_pos(world, obj, point)
    out = world.object_mat(obj) @ np.asarray(fp.direction, float)  # the drawer's way out
    yaw = s.natural_yaw(yaw_of(world.object_mat(obj)) + math.pi / 2)  # fingers close along the slide
    end = handle + out * (to - opening(world, obj, point))
    wps = s.transit(s.q, handle + [0.0, 0.0, ABOVE], yaw, AJAR)

    def line(to: np.ndarray, gripper: float, speed: float, label: str) -> list[Waypoint]:
        q = wps[-1].q  # a straight move keeps the heading the hand has reached
        return s.line(q, to, s.tcp(q)[1], gripper, speed, label)

    wps += line(handle, AJAR, SLOW_SPEED, "line")
    wps.append(Waypoint(wps[-1].q, CLOSED, 0.3, hold=0.5, label="close"))
    wps += line(end, CLOSED, SLIDE_SPEED, "slide")
    wps.append(Waypoint(wps[-1].q, OPEN, 0.3, hold=0.3, label="open"))
    wps += line(end + [0.0, 0.0, ABOVE], OPEN, SLOW_SPEED, "line")
    return MotionPlan(name, tuple(wps))


def goal_opening(world: World, obj: str, skill: str, point: str | None = None,
                 distance: float | None = None) -> float:
    """How far out ``skill`` (``open_drawer`` or ``close_drawer``) slides ``obj``'s drawer."""
    if skill == "close_drawer":
        return -PAST_SHUT
    if distance is not None:
        return float(distance)
    return handle_of(world, obj, point).stroke * world.object(obj).scale


@SKILLS.register("open_drawer")
def open_drawer(s: Skills, obj: str, point: str | None = None, distance: float | None = None) -> MotionPlan:
    """Pull ``obj``'s drawer out by its handle to ``distance`` metres (default: the handle's stroke)."""
    return slide(s, obj, goal_opening(s.world, obj, "open_drawer", point, distance), point, "open_drawer")


@SKILLS.register("close_drawer")
def close_drawer(s: Skills, obj: str, point: str | None = None) -> MotionPlan:
    """Push ``obj``'s drawer shut by its handle."""
    return slide(s, obj, goal_opening(s.world, obj, "close_drawer", point), point, "close_drawer")
