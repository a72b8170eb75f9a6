"""Hanging an object by its loop on a hook: the skill ``hang`` (a mug by its handle on a rack's peg).

The object's ``loop`` is a functional point in the middle of the opening that goes over the hook,
``direction`` the way the opening faces (a mug's handle: outward from the body); the host's ``hook``
is a functional point at the hook's free end, ``direction`` along the hook towards where it is
fixed (:mod:`vcage.assets.annotations`). The hand takes the grasp farthest from the loop, lifts,
turns the held object so that the opening's axis runs along the hook (its loop facing away from the
robot, the hand on the robot's side), carries the opening over the host and down to just
beyond the hook's end, threads it on along the hook, lowers it onto the hook, lets go and moves up:
one plan, open loop from the state it is planned in, like ``pick_and_place``.
"""

from __future__ import annotations

import math

import numpy as np

from vcage.assets.annotations import FunctionalPoint
from vcage.assets.catalog import CATALOG
from vcage.errors import SkillError
from vcage.geometry import rot_z, wrap_angle, yaw_of
from vcage.scene.spec import ROBOT_MOUNT
from vcage.sim.world import World
from vcage.skills.base import SKILLS, Skills
from vcage.skills.motion import MotionPlan
from vcage.skills.primitives import lift, move_line, move_to, open_gripper, rotate, taken

LIFT = 0.2  # metres above the table the held object is lifted to before it turns
OVER = 0.03  # the held object's bottom passes this far above the host's top on its way to the hook
BEFORE = 0.035  # the opening waits this far beyond the hook's end before threading
ON_HOOK = 0.03  # and ends this far along the hook from its end
DROP = 0.022  # the loop's upper bar is then lowered onto the hook
CLEAR = 0.06  # the open hand then moves up this far
THREAD_SPEED = 0.05  # metres per second while threading and lowering


def point_of(world: World, obj: str, kind: str, point: str | None = None) -> FunctionalPoint:
    """``obj``'s functional point of ``kind`` (``point``: the one of that name); SkillError if none."""
    otype = CATALOG.get(world.object(obj).type_name)
    fp = otype.point_of_kind(kind, point)
    if fp is None:
        having = CATALOG.with_point(kind)
        raise SkillError(f"{obj!r} ({otype.name}) has no {kind}" + (f" named {point!r}" if point else "")
                         + f"; objects with one: {having}")
    return fp


def hook_end(world: World, host: str, point: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The free end of ``host``'s hook (world) and its axis, pointing along the hook to where it is
    fixed."""
    fp, inst = point_of(world, host, "hook", point), world.object(host)
    rot = world.object_mat(host)
    return (world.object_pos(host) + rot @ (np.asarray(fp.pos) * inst.scale),
            rot @ np.asarray(fp.direction, float))


@SKILLS.register("hang")
def hang(s: Skills, obj: str, target: str, point: str | None = None) -> MotionPlan:
    """Hang ``obj`` by its loop (a mug's handle) on ``target``'s hook (a rack's peg).

    ``point``: the hook of that name (default: the first)."""
    return hung(s, obj, target, point)


def hung(s: Skills, obj: str, target: str, point: str | None = None, thread: float = 1.0) -> MotionPlan:
    """:func:`hang`, threading ``thread`` of the way from the waiting point onto the hook (1: all)."""
    world = s.world
    loop, inst = point_of(world, obj, "loop"), world.object(obj)
    end, axis = hook_end(world, target, point)
    pos, rot = world.object_pos(obj), world.object_mat(obj)
    hole = pos + rot @ (np.asarray(loop.pos) * inst.scale)
    grasps = sorted(CATALOG.get(inst.type_name).grasps,
                    key=lambda g: -float(np.linalg.norm(np.subtract(g.pos, loop.pos)[:2])))
    choice, plan = taken(s, obj, "hang", grasps[0].name)  # the grasp farthest from the loop
    # the opening faces across the hook (the hook runs through it), away from the robot of the two
    # ways: the object's body, and the hand holding it, stay on the robot's side of the hook
    facing = yaw_of(rot) + math.atan2(loop.direction[1], loop.direction[0])
    away = math.atan2(end[1] - ROBOT_MOUNT[1], end[0] - ROBOT_MOUNT[0])
    along = math.atan2(axis[1], axis[0])
    wanted = min((along - math.pi / 2, along + math.pi / 2), key=lambda a: abs(wrap_angle(a - away)))
    turn = wrap_angle(wanted - facing)
    offset = rot_z(turn) @ (hole - choice.pos)  # the loop relative to the TCP, once turned
    wait = end - axis * BEFORE - offset
    on = wait + axis * (BEFORE + ON_HOOK) * thread
    # the object comes down onto the waiting point from above the host, which it would hit on the way
    host = world.object(target)
    top = world.object_pos(target)[2] + CATALOG.get(host.type_name).size[2] * host.scale
    over = wait + [0.0, 0.0, max(0.0, top + OVER + loop.pos[2] * inst.scale - end[2])]
    steps = (lambda: lift(s, height=LIFT), lambda: rotate(s, turn), lambda: move_to(s, over),
             lambda: move_line(s, wait), lambda: move_line(s, on, speed=THREAD_SPEED),
             lambda: move_line(s, on - [0.0, 0.0, DROP], speed=THREAD_SPEED), lambda: open_gripper(s),
             lambda: move_line(s, on + [0.0, 0.0, CLEAR - DROP]))
    for step in steps:  # each planned from where the one before ends
        with s.after(plan):
            plan = plan + step()
    return MotionPlan("hang", plan.waypoints)

