"""Manipulation primitives, registered in ``SKILLS``. Each one is planned from the current world
state through :class:`~vcage.skills.base.Skills` and returns a :class:`MotionPlan`;
:meth:`Skills.do` plans and executes in one call.
"""

from __future__ import annotations

import math

import numpy as np

from vcage.assets.catalog import CATALOG
from vcage.errors import SkillError
from vcage.geometry import rot_z, wrap_angle, wrap_half_turn, yaw_of
from vcage.scene.spec import ROBOT_MOUNT
from vcage.sim.robot import HOME_QPOS
from vcage.sim.world import World
from vcage.skills.base import (
    APPROACH,
    CART_SPEED,
    CLOSED,
    FINGER_REACH,
    OPEN,
    SAFE_HEIGHT,
    SKILLS,
    SLOW_SPEED,
    TCP_MIN_ABOVE_TABLE,
    GraspChoice,
    Skills,
)
from vcage.skills.ik import down_rotation
from vcage.skills.motion import MotionPlan, Waypoint
from vcage.skills.placements import placement_frame

PLACE_CLEARANCE = 0.012  # metres above its resting height at which a placed object is let go
FACE_LIFT = 0.05  # metres turn_to_face lifts an object before turning it (as rotate_qrcode's expert did)
ELONGATED = 1.15  # long side over short side from which an object or a container's room has a long axis


# -- the primitives ------------------------------------------------------------------------------
@SKILLS.register("move_to")
def move_to(s: Skills, pos: np.ndarray, yaw: float | None = None, gripper: float | None = None) -> MotionPlan:
    """Move the TCP to ``pos`` (pointing down, heading ``yaw``) through free space."""
    yaw = s.tcp()[1] if yaw is None else yaw
    g = s.gripper if gripper is None else gripper
    return MotionPlan("move_to", tuple(s.transit(s.q, np.asarray(pos, float), yaw, g)))


@SKILLS.register("open_gripper")
def open_gripper(s: Skills) -> MotionPlan:
    """Open the hand fully where it is."""
    return MotionPlan("open_gripper", (Waypoint(s.q, OPEN, 0.3, hold=0.3, label="open"),))


@SKILLS.register("close_gripper")
def close_gripper(s: Skills) -> MotionPlan:
    """Close the hand where it is."""
    return MotionPlan("close_gripper", (Waypoint(s.q, CLOSED, 0.3, hold=0.5, label="close"),))


@SKILLS.register("grasp")
def grasp(s: Skills, obj: str, grasp_name: str | None = None) -> MotionPlan:
    """Approach ``obj`` from above along its best reachable grasp annotation and close the hand."""
    return taken(s, obj, "grasp", grasp_name)[1]


def taken(s: Skills, obj: str, skill: str, grasp_name: str | None = None,
          then_turn: float = 0.0) -> tuple[GraspChoice, MotionPlan]:
    """The grasp chosen on ``obj`` (see :meth:`~vcage.skills.base.Skills.choose_grasp`) and the plan,
    named ``skill``, that approaches it and closes the hand: the start of every skill that picks."""
    choice, wps = s.choose_grasp(obj, grasp_name, then_turn)
    wps.append(Waypoint(wps[-1].q, CLOSED, 0.3, hold=0.5, label="close"))
    return choice, MotionPlan(skill, tuple(wps))


@SKILLS.register("lift")
def lift(s: Skills, height: float = 0.12) -> MotionPlan:
    """Raise the hand (and whatever it holds) straight up to ``height`` above the table."""
    pos, yaw = s.tcp()
    target = np.array([pos[0], pos[1], max(pos[2], s.table_z) + height])
    return MotionPlan("lift", tuple(s.line(s.q, target, yaw, s.gripper, SLOW_SPEED, "lift")))


@SKILLS.register("retreat")
def retreat(s: Skills, home: bool = True) -> MotionPlan:
    """Move up to the safe height, then (optionally) back to the home posture."""
    pos, yaw = s.tcp()
    safe = s.table_z + SAFE_HEIGHT
    wps = []
    if pos[2] < safe:
        wps = s.line(s.q, np.array([pos[0], pos[1], safe]), yaw, s.gripper, CART_SPEED, "up")
    if home:
        q = wps[-1].q if wps else s.q
        wps.append(Waypoint(HOME_QPOS, s.gripper, s._duration(q, HOME_QPOS, 0.0, CART_SPEED), label="home"))
    return MotionPlan("retreat", tuple(wps))


def _held_offset(s: Skills, obj: str) -> np.ndarray:
    """Object origin minus the TCP position, measured now (accounts for any slip in the hand)."""
    return s.world.object_pos(obj) - s.tcp()[0]


def placement_target(s: Skills, target: str, placement: str | None = None) -> tuple[np.ndarray, float]:
    """World position (surface height) and yaw of ``target``'s placement region where it is now
    (:func:`~vcage.skills.placements.placement_frame`)."""
    center, rot, _, _ = placement_frame(s.world, target, placement)
    return center, yaw_of(rot)


@SKILLS.register("place")
def place(s: Skills, obj: str, target: str | None = None, placement: str | None = None,
          xy: tuple[float, float] | None = None, clearance: float = PLACE_CLEARANCE,
          yaw: float | None = None, offset: np.ndarray | None = None) -> MotionPlan:
    """Put the held ``obj`` onto ``target``'s placement annotation (or the table at ``xy``) and release.

    ``offset`` is the object origin relative to the TCP; measured from the world when not given.
    """
    if target is not None:
        surface, _ = placement_target(s, target, placement)
    elif xy is not None:
        surface = np.array([xy[0], xy[1], s.table_z])
    else:
        raise SkillError("place needs a target object or a table position xy")
    offset = _held_offset(s, obj) if offset is None else np.asarray(offset)
    hand_yaw = s.tcp()[1] if yaw is None else s.natural_yaw(yaw)
    return _lower_and_release(s, surface, offset, hand_yaw, clearance)


def _lower_and_release(s: Skills, surface: np.ndarray, offset: np.ndarray, hand_yaw: float,
                       clearance: float) -> MotionPlan:
    """Carry the held object above ``surface``, lower it onto it, release and withdraw."""
    goal = surface - offset + [0.0, 0.0, clearance]
    goal[2] = max(goal[2], s.table_z + TCP_MIN_ABOVE_TABLE)
    wps = s.transit(s.q, goal + [0.0, 0.0, APPROACH], hand_yaw, CLOSED)
    wps += s.line(wps[-1].q, goal, hand_yaw, CLOSED, SLOW_SPEED, "lower")
    wps.append(Waypoint(wps[-1].q, OPEN, 0.3, hold=0.3, label="release"))
    up = goal + [0.0, 0.0, 0.08]
    wps += s.line(wps[-1].q, up, hand_yaw, OPEN, SLOW_SPEED, "withdraw")
    return MotionPlan("place", tuple(wps))


@SKILLS.register("pick_and_place")
def pick_and_place(s: Skills, obj: str, target: str | None = None, placement: str | None = None,
                   xy: tuple[float, float] | None = None, grasp_name: str | None = None) -> MotionPlan:
    """Grasp, lift, place and withdraw, planned open loop from the current state."""
    choice, plan = taken(s, obj, "pick_and_place", grasp_name)
    offset = s.world.object_pos(obj) - choice.pos  # where the object will sit relative to the TCP
    with s.after(plan):
        plan = plan + lift(s)
    with s.after(plan):
        room = _room_axis(s, obj, target, placement) if target is not None else None
        if room is not None:
            plan = plan + _turned_in(s, obj, *room, offset)
        else:
            plan = plan + place(s, obj, target, placement, xy, offset=offset)
    return MotionPlan("pick_and_place", plan.waypoints)


def _room_axis(s: Skills, obj: str, target: str,
               placement: str | None) -> tuple[np.ndarray, float] | None:
    """Where ``target``'s container holds the held ``obj`` (its surface) and the yaw along which
    ``obj``'s long side should lie there, or None where it need not turn (not a container; a round
    one; ``obj`` about as wide as long). In a drawer it lies across the slide: put in lengthwise, it
    can catch on the body when the drawer is pushed shut. In another container it lies along the
    longer side: across, a loaf can come to rest on both rims of a small basket."""
    place = CATALOG.get(s.world.object(target).type_name).placement(placement)
    if place.kind != "in":
        return None
    surface, host_yaw = placement_target(s, target, placement)
    if place.joint:
        return surface, host_yaw + math.pi / 2  # the drawer slides along its x
    hx, hy = place.half_size
    sx, sy = CATALOG.get(s.world.object(obj).type_name).size[:2]
    if max(hx, hy) < ELONGATED * min(hx, hy) or max(sx, sy) < ELONGATED * min(sx, sy):
        return None
    return surface, host_yaw + (0.0 if hx >= hy else math.pi / 2)


def _turned_in(s: Skills, obj: str, surface: np.ndarray, room: float, offset: np.ndarray) -> MotionPlan:
    """Put the held ``obj`` (origin at ``offset`` from the TCP) down on ``surface`` in a container with
    its long side along ``room``, turning the hand by the smallest turn that does it."""
    sx, sy = CATALOG.get(s.world.object(obj).type_name).size[:2]
    long_axis = yaw_of(s.world.object_mat(obj)) + (0.0 if sx >= sy else math.pi / 2)
    turn = wrap_half_turn(room - long_axis)
    _, hand_yaw = s.tcp()
    return _lower_and_release(s, surface, rot_z(turn) @ offset, hand_yaw + turn, PLACE_CLEARANCE)


@SKILLS.register("press")
def press(s: Skills, obj: str, point: str | None = None, depth: float = 0.004,
          hold: float = 0.3) -> MotionPlan:
    """Press ``obj``'s functional point down by its stroke plus ``depth`` with the closed hand."""
    inst = s.world.object(obj)
    fp = CATALOG.get(inst.type_name).functional_point(point)
    pos, rot = s.world.object_pos(obj), s.world.object_mat(obj)
    top = pos + rot @ (np.asarray(fp.pos) * inst.scale)
    # the closed finger tips are FINGER_REACH below the TCP
    contact = top + [0.0, 0.0, FINGER_REACH]
    bottom = contact - [0.0, 0.0, fp.stroke * inst.scale + depth]
    # A round push button is the same from every side: the hand keeps its heading rather than turn
    # the wrist by up to 90 degrees on the object's yaw, which says nothing about the button (and
    # would make demonstrations differ by a wrist turn that a policy cannot read off the scene).
    # Levers and switches are pressed across their axis.
    yaw = s.tcp()[1] if fp.kind == "button" else s.natural_yaw(yaw_of(rot) + math.pi / 2)
    wps = [Waypoint(s.q, CLOSED, 0.3, label="close")]
    wps += s.transit(wps[-1].q, contact + [0.0, 0.0, 0.06], yaw, CLOSED)
    wps += s.line(wps[-1].q, bottom, yaw, CLOSED, 0.08, "press")
    wps[-1] = Waypoint(wps[-1].q, CLOSED, wps[-1].duration, hold=hold, label="press")
    wps += s.line(wps[-1].q, contact + [0.0, 0.0, 0.06], yaw, CLOSED, SLOW_SPEED, "release")
    return MotionPlan("press", tuple(wps))


@SKILLS.register("push")
def push(s: Skills, obj: str, direction: tuple[float, float], distance: float,
         height: float = 0.012) -> MotionPlan:
    """Slide ``obj`` along ``direction`` by ``distance`` with the closed fingers, low over the table."""
    d = np.array([direction[0], direction[1], 0.0])
    if np.linalg.norm(d) < 1e-9:
        raise SkillError("push direction must be non-zero")
    d /= np.linalg.norm(d)
    inst = s.world.object(obj)
    radius = CATALOG.get(inst.type_name).footprint_radius * inst.scale
    center = s.world.object_pos(obj)
    z = s.table_z + FINGER_REACH + height
    start = np.array([center[0], center[1], z]) - d * (radius + 0.03)
    end = start + d * (distance + 0.0)
    yaw = s.natural_yaw(math.atan2(d[1], d[0]) + math.pi / 2)
    wps = [Waypoint(s.q, CLOSED, 0.3, label="close")]
    wps += s.transit(wps[-1].q, start + [0.0, 0.0, 0.05], yaw, CLOSED)
    wps += s.line(wps[-1].q, start, yaw, CLOSED, SLOW_SPEED, "lower")
    wps += s.line(wps[-1].q, end, yaw, CLOSED, 0.1, "push")
    wps += s.line(wps[-1].q, end + [0.0, 0.0, 0.08], yaw, CLOSED, SLOW_SPEED, "withdraw")
    return MotionPlan("push", tuple(wps))


@SKILLS.register("rotate")
def rotate(s: Skills, angle: float) -> MotionPlan:
    """Turn the hand about its approach axis by ``angle`` radians, keeping the TCP in place."""
    pos, yaw = s.tcp()
    q = s.ik.solve(pos, down_rotation(yaw + angle), s.q)
    return MotionPlan("rotate", (Waypoint(q, s.gripper, max(0.5, abs(angle) / 1.0), label="rotate"),))


# -- additions for the RoboTwin-style tasks: turning while carrying, straight moves, shaking -------
@SKILLS.register("turn_and_place")
def turn_and_place(s: Skills, obj: str, turn: float, target: str | None = None,
                   placement: str | None = None, xy: tuple[float, float] | None = None,
                   clearance: float = PLACE_CLEARANCE, offset: np.ndarray | None = None) -> MotionPlan:
    """Put the held ``obj`` down like :func:`place`, turned by ``turn`` radians about the vertical
    (the hand turns by exactly that much, so the object's heading changes by ``turn``). ``offset``
    is the object origin relative to the TCP; measured from the world when not given."""
    if target is not None:
        surface, _ = placement_target(s, target, placement)
    elif xy is not None:
        surface = np.array([xy[0], xy[1], s.table_z])
    else:
        raise SkillError("turn_and_place needs a target object or a table position xy")
    _, hand_yaw = s.tcp()
    held = _held_offset(s, obj) if offset is None else np.asarray(offset)
    turned = rot_z(turn) @ held  # the object turns about the TCP with the hand
    return MotionPlan("turn_and_place",
                      _lower_and_release(s, surface, turned, hand_yaw + turn, clearance).waypoints)


def turn_to_face_robot(world: World, obj: str, at: tuple[float, float] | None = None,
                       point: str | None = None) -> float:
    """The turn (within ±pi) after which ``obj``'s functional point faces the robot's base, once
    ``obj`` stands at ``at`` (default: where it is)."""
    d = CATALOG.get(world.object(obj).type_name).functional_point(point).direction
    out = math.atan2(d[1], d[0]) + yaw_of(world.object_mat(obj))
    pos = world.object_pos(obj) if at is None else at
    wanted = math.atan2(ROBOT_MOUNT[1] - pos[1], ROBOT_MOUNT[0] - pos[0])
    return wrap_angle(wanted - out)


@SKILLS.register("turn_to_face")
def turn_to_face(s: Skills, obj: str, target: str | None = None, placement: str | None = None,
                 xy: tuple[float, float] | None = None, point: str | None = None,
                 grasp_name: str | None = None) -> MotionPlan:
    """Grasp, lift and put down ``obj`` turned so that its face points at the robot.

    It goes on ``target``'s placement, on the table at ``xy``, or back where it stood; ``point``
    names the functional point to turn (default: the type's face, see ``ObjectType.face``)."""
    return turned_to_face(s, obj, target, placement, xy, point, grasp_name)


def turned_to_face(s: Skills, obj: str, target: str | None = None, placement: str | None = None,
                   xy: tuple[float, float] | None = None, point: str | None = None,
                   grasp_name: str | None = None, share: float = 1.0) -> MotionPlan:
    """:func:`turn_to_face`, turning ``share`` of the turn it needs (1: all of it)."""
    if point is None:
        face = CATALOG.get(s.world.object(obj).type_name).face
        if face is None:
            raise SkillError(f"{obj} ({s.world.object(obj).type_name}) has no face to turn towards the robot")
        point = face.name
    if target is not None:
        at = tuple(placement_target(s, target, placement)[0][:2])
    else:
        here = s.world.object_pos(obj)
        at = (float(here[0]), float(here[1])) if xy is None else (float(xy[0]), float(xy[1]))
    turn = share * turn_to_face_robot(s.world, obj, (at[0], at[1]), point)
    choice, plan = taken(s, obj, "turn_to_face", grasp_name, then_turn=turn)  # the wrist turns about now
    offset = s.world.object_pos(obj) - choice.pos  # where the object will sit relative to the TCP
    with s.after(plan):
        plan = plan + lift(s, height=FACE_LIFT)
    with s.after(plan):
        plan = plan + turn_and_place(s, obj, turn, target, placement,
                                     None if target is not None else (at[0], at[1]), offset=offset)
    return MotionPlan("turn_to_face", plan.waypoints)


@SKILLS.register("move_line")
def move_line(s: Skills, pos: np.ndarray, speed: float = SLOW_SPEED, hold: float = 0.0) -> MotionPlan:
    """Move the TCP on a straight line to ``pos``, keeping its heading and the gripper as they are
    (to strike, pull or slide in contact); ``hold`` keeps the end pose that many seconds."""
    _, yaw = s.tcp()
    wps = s.line(s.q, np.asarray(pos, float), yaw, s.gripper, speed, "line")
    if hold > 0:
        wps[-1] = Waypoint(wps[-1].q, wps[-1].gripper, wps[-1].duration, hold=hold, label="line")
    return MotionPlan("move_line", tuple(wps))


@SKILLS.register("shake")
def shake(s: Skills, amplitude: float = 0.04, cycles: int = 3, heading: float = math.pi / 2,
          speed: float = 0.25) -> MotionPlan:
    """Shake the hand (and what it holds) ``cycles`` times by ``amplitude`` either way along the
    horizontal direction ``heading`` (radians from +x; default along y), ending where it started."""
    if amplitude <= 0 or cycles < 1:
        raise SkillError("shake needs a positive amplitude and at least one cycle")
    pos, yaw = s.tcp()
    d = np.array([math.cos(heading), math.sin(heading), 0.0]) * amplitude
    wps: list[Waypoint] = []
    q = s.q
    for target in [pos + d, pos - d] * cycles + [pos]:
        wps += s.line(q, target, yaw, s.gripper, speed, "shake")
        q = wps[-1].q
    return MotionPlan("shake", tuple(wps))
