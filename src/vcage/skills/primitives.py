"""Manipulation primitives. Each one is planned from the current world state and returns a
:class:`MotionPlan`; :meth:`Skills.do` plans and executes in one call.

Grasps and placements come from the catalog's annotations of the objects involved. Plans are open
loop once computed: grasps can slip and presses can miss under noise, which is what the critic is
for later in the pipeline.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from vcage.assets.annotations import Grasp
from vcage.assets.catalog import CATALOG
from vcage.errors import IKError, SkillError
from vcage.geometry import wrap_angle, yaw_of
from vcage.registry import Registry
from vcage.scene.spec import ROBOT_MOUNT
from vcage.sim.robot import HOME_QPOS
from vcage.sim.world import World
from vcage.skills.ik import IKSolver, down_rotation
from vcage.skills.motion import MotionPlan, Waypoint
from vcage.skills.playback import Player

SKILLS: Registry[Callable[..., MotionPlan]] = Registry("skill")

OPEN, CLOSED = 1.0, 0.0
FINGER_REACH = 0.035  # finger tips below the TCP
TCP_MIN_ABOVE_TABLE = 0.034
SAFE_HEIGHT = 0.22  # transit height above the table
APPROACH = 0.10  # pre-grasp / pre-place height above the target
CART_SPEED = 0.30  # m/s in free space
SLOW_SPEED = 0.12  # m/s near objects
JOINT_SPEED = 1.2  # rad/s cap on the fastest joint


@dataclass(frozen=True)
class GraspChoice:
    obj: str
    grasp: Grasp
    pos: np.ndarray  # TCP position in the world
    yaw: float  # TCP heading


class Skills:
    """Plans primitives on a world and executes them with one :class:`Player`."""

    def __init__(self, world: World, player: Player | None = None) -> None:
        self.world = world
        self.ik = IKSolver(ROBOT_MOUNT)
        self.player = player or Player(world)
        self.table_z = world.table_top()
        self._cursor: tuple[np.ndarray, float] | None = None

    # -- state of the plan being built ---------------------------------------------------------
    @property
    def q(self) -> np.ndarray:
        """Arm command the next plan starts from (the player's, or the end of a plan being chained)."""
        return (self._cursor[0] if self._cursor else self.player.q_cmd).copy()

    @property
    def gripper(self) -> float:
        return self._cursor[1] if self._cursor else self.player.gripper_cmd

    @contextmanager
    def after(self, plan: MotionPlan) -> Iterator[None]:
        """Plan the next skill as if ``plan`` had been executed (for composite skills)."""
        saved = self._cursor
        if plan.waypoints:
            self._cursor = (plan.final_q, plan.final_gripper)
        try:
            yield
        finally:
            self._cursor = saved

    def tcp(self, q: np.ndarray | None = None) -> tuple[np.ndarray, float]:
        pos, rot = self.ik.fk(self.q if q is None else q)
        return pos, yaw_of(rot)

    def do(self, name: str, **kwargs: object) -> MotionPlan:
        """Plan skill ``name`` from the current state and execute it."""
        plan = SKILLS.get(name)(self, **kwargs)
        self.player.run(plan)
        return plan

    # -- building blocks ----------------------------------------------------------------------
    def _duration(self, q0: np.ndarray, q1: np.ndarray, dist: float, speed: float) -> float:
        return max(0.25, dist / speed, float(np.max(np.abs(q1 - q0))) / JOINT_SPEED)

    def line(self, start_q: np.ndarray, pos: np.ndarray, yaw: float, gripper: float,
             speed: float = SLOW_SPEED, label: str = "") -> list[Waypoint]:
        """Waypoints moving the TCP on a straight line from its pose at ``start_q`` to ``pos``."""
        p0, yaw0 = self.tcp(start_q)
        dist = float(np.linalg.norm(pos - p0))
        n = max(1, math.ceil(dist / 0.03))
        dyaw = wrap_angle(yaw - yaw0)
        wps, q = [], start_q
        for k in range(1, n + 1):
            s = k / n
            target = p0 + s * (pos - p0)
            q_next = self.ik.solve(target, down_rotation(yaw0 + s * dyaw), q)
            wps.append(Waypoint(q_next, gripper, self._duration(q, q_next, dist / n, speed) if n > 1
                                else self._duration(q, q_next, dist, speed), label=label))
            q = q_next
        if n > 1:  # re-time the whole line at constant speed: min-jerk per segment would stutter
            total = max(0.3, dist / speed)
            wps = [Waypoint(w.q, w.gripper, max(total / n, w.duration), label=w.label) for w in wps]
        return wps

    def transit(self, start_q: np.ndarray, pos: np.ndarray, yaw: float, gripper: float) -> list[Waypoint]:
        """Up to the safe height, across, and down to ``pos`` (which should be above the target)."""
        p0, _ = self.tcp(start_q)
        safe = self.table_z + SAFE_HEIGHT
        wps: list[Waypoint] = []
        q = start_q
        if p0[2] < safe - 0.02:
            wps += self.line(q, np.array([p0[0], p0[1], safe]), self.tcp(q)[1], gripper, CART_SPEED, "up")
            q = wps[-1].q
        above = np.array([pos[0], pos[1], max(safe, pos[2])])
        q_above = self.ik.solve(above, down_rotation(yaw), q)
        dist = float(np.linalg.norm(above - self.tcp(q)[0]))
        wps.append(Waypoint(q_above, gripper, self._duration(q, q_above, dist, CART_SPEED), label="across"))
        if pos[2] < above[2] - 1e-3:
            wps += self.line(q_above, np.asarray(pos, float), yaw, gripper, CART_SPEED, "down")
        return wps

    def natural_yaw(self, yaw: float, period: float = math.pi) -> float:
        """Among ``yaw + k * period`` the one closest to the current hand heading."""
        _, current = self.tcp()
        k = round((current - yaw) / period)
        return wrap_angle(yaw + k * period)

    # -- grasp selection ----------------------------------------------------------------------
    def grasp_candidates(self, obj: str, name: str | None = None) -> list[GraspChoice]:
        inst = self.world.object(obj)
        otype = CATALOG.get(inst.type_name)
        grasps = [g for g in otype.grasps if name is None or g.name == name]
        if not grasps:
            raise SkillError(
                f"{obj} ({inst.type_name}) has no grasp {name or ''!r}; annotated: "
                f"{[g.name for g in otype.grasps] or 'none'}"
            )
        pos, rot = self.world.object_pos(obj), self.world.object_mat(obj)
        out = []
        for g in grasps:
            p = pos + rot @ (np.asarray(g.pos) * inst.scale)
            p[2] = max(p[2], self.table_z + TCP_MIN_ABOVE_TABLE)
            out.append(GraspChoice(obj, g, p, self.natural_yaw(yaw_of(rot) + g.yaw)))
        _, current = self.tcp()
        out.sort(key=lambda c: abs(wrap_angle(c.yaw - current)))
        return out

    def choose_grasp(self, obj: str, name: str | None = None) -> tuple[GraspChoice, list[Waypoint]]:
        """The first annotated grasp whose approach and grasp poses are reachable, with its plan."""
        errors = []
        for cand in self.grasp_candidates(obj, name):
            try:
                pre = cand.pos + [0.0, 0.0, APPROACH]
                wps = self.transit(self.q, pre, cand.yaw, OPEN)
                wps += self.line(wps[-1].q, cand.pos, cand.yaw, OPEN, SLOW_SPEED, "descend")
                return cand, wps
            except IKError as exc:
                errors.append(f"{cand.grasp.name}: {exc}")
        raise SkillError(f"no reachable grasp on {obj}: " + "; ".join(errors))


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
    _, wps = s.choose_grasp(obj, grasp_name)
    wps.append(Waypoint(wps[-1].q, CLOSED, 0.3, hold=0.5, label="close"))
    return MotionPlan("grasp", tuple(wps))


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
    """World position (surface height) and yaw of ``target``'s placement annotation."""
    inst = s.world.object(target)
    otype = CATALOG.get(inst.type_name)
    place = otype.placement(placement)
    pos, rot = s.world.object_pos(target), s.world.object_mat(target)
    return pos + rot @ (np.asarray(place.pos) * inst.scale), yaw_of(rot)


@SKILLS.register("place")
def place(s: Skills, obj: str, target: str | None = None, placement: str | None = None,
          xy: tuple[float, float] | None = None, clearance: float = 0.012,
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
    choice, wps = s.choose_grasp(obj, grasp_name)
    wps.append(Waypoint(wps[-1].q, CLOSED, 0.3, hold=0.5, label="close"))
    plan = MotionPlan("pick_and_place", tuple(wps))
    offset = s.world.object_pos(obj) - choice.pos  # where the object will sit relative to the TCP
    with s.after(plan):
        plan = plan + lift(s)
    with s.after(plan):
        plan = plan + place(s, obj, target, placement, xy, offset=offset)
    return MotionPlan("pick_and_place", plan.waypoints)


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
    yaw = s.natural_yaw(yaw_of(rot) + math.pi / 2)
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
