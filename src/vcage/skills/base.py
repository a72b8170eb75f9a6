"""The context every skill is planned in: a world, IK, the command the next plan starts from, and
the motion building blocks (straight lines, transits at a safe height, grasp choice).

Grasps and placements come from the catalog's annotations of the objects involved. Plans are open
loop once computed: grasps can slip and presses can miss under noise, which is what the critic is
for later in the pipeline. The primitives themselves are registered in ``SKILLS`` by
:mod:`vcage.skills.primitives`, which the package imports.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from vcage.assets.annotations import Grasp
from vcage.assets.catalog import CATALOG
from vcage.errors import IKError, SkillError
from vcage.geometry import wrap_angle, yaw_of
from vcage.registry import Registry
from vcage.scene.spec import ROBOT_MOUNT
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


class SkillFault(Protocol):
    """Plans a perturbed version of a skill call, or None to plan it as usual (see
    :mod:`vcage.skills.faults`: silent failures injected to test critics)."""

    def plan(self, skills: Skills, name: str, kwargs: dict[str, object]) -> MotionPlan | None: ...


@dataclass(frozen=True)
class GraspChoice:
    obj: str
    grasp: Grasp
    pos: np.ndarray  # TCP position in the world
    yaw: float  # TCP heading


class Skills:
    """Plans primitives on a world and executes them with one :class:`Player`."""

    def __init__(self, world: World, player: Player | None = None, fault: SkillFault | None = None) -> None:
        self.world = world
        self.fault = fault  # None: every skill is planned as registered
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
        plan = self.fault.plan(self, name, dict(kwargs)) if self.fault is not None else None
        if plan is None:
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
    def grasp_candidates(self, obj: str, name: str | None = None,
                         then_turn: float = 0.0) -> list[GraspChoice]:
        """``obj``'s annotated grasps (``name``: that one), each at the hand heading, among its yaw and
        the yaw half a turn round (the fingers are symmetric), closest to the current heading; for an
        object the hand will turn by ``then_turn`` while holding it, the heading halfway through that
        turn is closest (the wrist then starts and ends the turn at most a quarter turn plus half of
        it away from where it is)."""
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
            yaw = self.natural_yaw(yaw_of(rot) + g.yaw + then_turn / 2) - then_turn / 2
            out.append(GraspChoice(obj, g, p, yaw))
        _, current = self.tcp()
        out.sort(key=lambda c: abs(wrap_angle(c.yaw - current)))
        return out

    def choose_grasp(self, obj: str, name: str | None = None,
                     then_turn: float = 0.0) -> tuple[GraspChoice, list[Waypoint]]:
        """The first annotated grasp whose approach and grasp poses are reachable, with its plan
        (``then_turn``: see :meth:`grasp_candidates`)."""
        errors = []
        for cand in self.grasp_candidates(obj, name, then_turn):
            try:
                pre = cand.pos + [0.0, 0.0, APPROACH]
                wps = self.transit(self.q, pre, cand.yaw, OPEN)
                wps += self.line(wps[-1].q, cand.pos, cand.yaw, OPEN, SLOW_SPEED, "descend")
                return cand, wps
            except IKError as exc:
                errors.append(f"{cand.grasp.name}: {exc}")
        raise SkillError(f"no reachable grasp on {obj}: " + "; ".join(errors))
