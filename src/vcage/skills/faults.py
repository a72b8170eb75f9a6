"""Silent failures injected into skills: the code runs without error, the goal is missed.

A critic exists to catch failures that raise nothing: a release too high or too late, a place off
target or on an edge, the wrong object moved, a press too light or beside the button, a neighbour
knocked over, a turn short of its angle, a stroke that stops short, a shake too weak, a drawer
slid only part of the way. Each fault here is a named, seeded perturbation of one skill call,
registered in ``FAULTS``; a :class:`FaultInjector` built from a frozen :class:`FaultConfig` is
given to :class:`~vcage.skills.base.Skills` (``Skills(world, fault=FaultInjector(cfg))``) and
replaces the plan of the chosen call (or, for faults that act on the result, adds to the next
call's plan).

A fault changes what the robot does, never the simulator's state directly: the failure happens in
MuJoCo like any other rollout, and whether the goal was missed is for the oracle to say afterwards
(an injected fault can still succeed: a dropped block may land on its pad).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from vcage.assets.catalog import CATALOG
from vcage.errors import ConfigError
from vcage.geometry import yaw_of
from vcage.registry import Registry
from vcage.skills.base import (
    APPROACH,
    CLOSED,
    FINGER_REACH,
    OPEN,
    SAFE_HEIGHT,
    SKILLS,
    SLOW_SPEED,
    TCP_MIN_ABOVE_TABLE,
    Skills,
)
from vcage.skills.drawers import goal_opening, opening, slide
from vcage.skills.hanging import hung
from vcage.skills.motion import MotionPlan, Waypoint
from vcage.skills.primitives import (
    lift,
    move_line,
    placement_target,
    press,
    push,
    shake,
    taken,
    turn_and_place,
    turned_to_face,
)

Args = Mapping[str, Any]
Perturb = Callable[[Skills, str, Args, np.random.Generator], MotionPlan | None]


@dataclass(frozen=True)
class FaultSpec:
    """A named perturbation of the skills in ``skills``. ``perturb(skills, skill, args, rng)``
    plans the faulty call (None: not applicable here). With ``after``, the fault acts on the
    call's result: the call runs as planned and the fault's plan is put before the next call."""

    name: str
    skills: tuple[str, ...]
    doc: str
    perturb: Perturb
    after: bool = False


FAULTS: Registry[FaultSpec] = Registry("fault", error=ConfigError)


def _fault(name: str, skills: tuple[str, ...], doc: str, after: bool = False) -> Callable[[Perturb], Perturb]:
    def deco(fn: Perturb) -> Perturb:
        FAULTS.add(name, FaultSpec(name, skills, doc, fn, after))
        return fn
    return deco


@dataclass(frozen=True)
class FaultConfig:
    """Inject fault ``name`` into call number ``occurrence`` (0: the first) of ``skill`` (None: of
    any skill the fault applies to), with random magnitudes drawn from ``seed``."""

    name: str
    skill: str | None = None
    occurrence: int = 0
    seed: int = 0

    def __post_init__(self) -> None:
        spec = FAULTS.get(self.name)  # an unknown name lists the valid ones
        if self.skill is not None and self.skill not in spec.skills:
            raise ConfigError(f"fault {self.name!r} applies to {', '.join(spec.skills)}, not {self.skill!r}")
        if isinstance(self.occurrence, bool) or not isinstance(self.occurrence, int) or self.occurrence < 0:
            raise ConfigError(f"fault occurrence must be an integer >= 0, got {self.occurrence!r}")


def faults_for(skill: str) -> list[str]:
    """Names of the faults that perturb ``skill``."""
    return [spec.name for spec in FAULTS.values() if skill in spec.skills]


class FaultInjector:
    """The :class:`~vcage.skills.base.SkillFault` hook of a :class:`Skills`: perturbs one call.

    ``applied`` says whether the fault was planned (False when it did not apply, e.g. no other
    object to grasp by mistake); ``note`` what it did.
    """

    def __init__(self, config: FaultConfig) -> None:
        self.config, self.spec = config, FAULTS.get(config.name)
        self.rng = np.random.default_rng(config.seed)
        self.calls = 0
        self.applied = False
        self.note = ""
        self._pending: tuple[str, dict[str, object]] | None = None

    def plan(self, skills: Skills, name: str, kwargs: dict[str, object]) -> MotionPlan | None:
        if self._pending is not None:  # an ``after`` fault, planned now that its call has run
            skill, args = self._pending
            self._pending = None
            first = self.spec.perturb(skills, skill, args, self.rng)
            if first is None:
                return None
            self._applied(skill)
            with skills.after(first):
                rest = SKILLS.get(name)(skills, **kwargs)
            return first + rest
        if name not in self.spec.skills or self.config.skill not in (None, name):
            return None
        k, self.calls = self.calls, self.calls + 1
        if k != self.config.occurrence:
            return None
        if self.spec.after:
            self._pending = (name, kwargs)
            return None
        out = self.spec.perturb(skills, name, kwargs, self.rng)
        if out is not None:
            self._applied(name)
        return out

    def _applied(self, skill: str) -> None:
        self.applied = True
        self.note = f"{self.spec.name} on {skill} call {self.config.occurrence}"


# -- building blocks --------------------------------------------------------------------------------

def _direction(rng: np.random.Generator) -> np.ndarray:
    a = rng.uniform(0.0, 2 * math.pi)
    return np.array([math.cos(a), math.sin(a), 0.0])


def _surface(s: Skills, args: Args) -> np.ndarray:
    """Where the call would put the object: the target's placement surface or the table at xy."""
    if args.get("target") is not None:
        return placement_target(s, str(args["target"]), args.get("placement"))[0]
    xy = args["xy"]
    return np.array([float(xy[0]), float(xy[1]), s.table_z])


def _pick(s: Skills, obj: str, grasp_name: str | None) -> tuple[MotionPlan, np.ndarray]:
    """Grasp and lift ``obj``; the plan and the object's origin relative to the TCP."""
    choice, plan = taken(s, obj, "pick_and_place", grasp_name)
    offset = s.world.object_pos(obj) - choice.pos
    with s.after(plan):
        plan = plan + lift(s)
    return plan, offset


def _lower(s: Skills, plan: MotionPlan, surface: np.ndarray, offset: np.ndarray,
           clearance: float = 0.012) -> MotionPlan:
    """After ``plan``: carry the held object over ``surface`` and lower it to ``clearance`` above."""
    with s.after(plan):
        yaw = s.tcp()[1]
        goal = surface - offset + [0.0, 0.0, clearance]
        goal[2] = max(goal[2], s.table_z + TCP_MIN_ABOVE_TABLE)
        wps = s.transit(s.q, goal + [0.0, 0.0, APPROACH], yaw, CLOSED)
        wps += s.line(wps[-1].q, goal, yaw, CLOSED, SLOW_SPEED, "lower")
    return plan + MotionPlan("pick_and_place", tuple(wps))


def _release(s: Skills, plan: MotionPlan, rise: float = 0.08) -> MotionPlan:
    """After ``plan``: open the hand where it is and withdraw ``rise`` upwards."""
    with s.after(plan):
        pos, yaw = s.tcp()
        wps = [Waypoint(s.q, OPEN, 0.3, hold=0.3, label="release")]
        wps += s.line(wps[-1].q, pos + [0.0, 0.0, rise], yaw, OPEN, SLOW_SPEED, "withdraw")
    return plan + MotionPlan("pick_and_place", tuple(wps))


def _place_at(s: Skills, args: Args, surface: np.ndarray, clearance: float = 0.012) -> MotionPlan:
    obj = str(args["obj"])
    plan, offset = _pick(s, obj, args.get("grasp_name"))
    return _release(s, _lower(s, plan, surface, offset, clearance))


def _others(s: Skills, args: Args, has: Callable[[str], bool]) -> list[str]:
    """Objects other than the call's, nearest to its object first, for which ``has`` holds."""
    skip = {args.get("obj"), args.get("target")}
    here = s.world.object_pos(str(args["obj"]))[:2]
    names = [n for n in s.world.object_names if n not in skip and has(n)]
    return sorted(names, key=lambda n: float(np.linalg.norm(s.world.object_pos(n)[:2] - here)))


def _graspable(s: Skills, name: str) -> bool:
    return bool(CATALOG.get(s.world.object(name).type_name).grasps)


def _pressable(s: Skills, name: str) -> bool:
    return any(fp.joint for fp in CATALOG.get(s.world.object(name).type_name).functional_points)


# -- pick_and_place ---------------------------------------------------------------------------------

@_fault("off_target", ("pick_and_place",), "place 6-12 cm from the target, in a random direction")
def _off_target(s: Skills, skill: str, args: Args, rng: np.random.Generator) -> MotionPlan:
    return _place_at(s, args, _surface(s, args) + _direction(rng) * rng.uniform(0.06, 0.12))


@_fault("on_edge", ("pick_and_place",), "place with the object's centre at the edge of the target's "
        "region: it overhangs, tips or slides off")
def _on_edge(s: Skills, skill: str, args: Args, rng: np.random.Generator) -> MotionPlan | None:
    if args.get("target") is None:
        return None
    target = str(args["target"])
    inst = s.world.object(target)
    half = np.asarray(CATALOG.get(inst.type_name).placement(args.get("placement")).half_size) * inst.scale
    rot = s.world.object_mat(target)
    axis = int(rng.integers(2))
    local = np.zeros(3)
    local[axis] = (half[axis] + rng.uniform(0.01, 0.025)) * rng.choice([-1.0, 1.0])
    return _place_at(s, args, _surface(s, args) + rot @ local)


@_fault("release_high", ("pick_and_place",), "open the hand 8-15 cm above the target: the object drops")
def _release_high(s: Skills, skill: str, args: Args, rng: np.random.Generator) -> MotionPlan:
    return _place_at(s, args, _surface(s, args), clearance=rng.uniform(0.08, 0.15))


@_fault("release_early", ("pick_and_place",), "open the hand on the way, at transit height")
def _release_early(s: Skills, skill: str, args: Args, rng: np.random.Generator) -> MotionPlan:
    plan, _ = _pick(s, str(args["obj"]), args.get("grasp_name"))
    with s.after(plan):
        start, yaw = s.tcp()
        end = _surface(s, args)
        mid = start + rng.uniform(0.3, 0.7) * (end - start)
        mid[2] = s.table_z + SAFE_HEIGHT
        plan = plan + MotionPlan("pick_and_place", tuple(s.transit(s.q, mid, yaw, CLOSED)))
    return _release(s, plan)


@_fault("release_late", ("pick_and_place",), "lower onto the target, keep holding, lift 4-8 cm and "
        "move 8-12 cm aside, then open")
def _release_late(s: Skills, skill: str, args: Args, rng: np.random.Generator) -> MotionPlan:
    plan, offset = _pick(s, str(args["obj"]), args.get("grasp_name"))
    plan = _lower(s, plan, _surface(s, args), offset)
    with s.after(plan):
        pos, yaw = s.tcp()
        up = pos + [0.0, 0.0, rng.uniform(0.04, 0.08)]
        wps = s.line(s.q, up, yaw, CLOSED, SLOW_SPEED, "lift")
        wps += s.line(wps[-1].q, up + _direction(rng) * rng.uniform(0.08, 0.12), yaw, CLOSED,
                      SLOW_SPEED, "drag")
        plan = plan + MotionPlan("pick_and_place", tuple(wps))
    return _release(s, plan)


@_fault("no_release", ("pick_and_place",), "never open the hand: the object is carried away")
def _no_release(s: Skills, skill: str, args: Args, rng: np.random.Generator) -> MotionPlan:
    plan = SKILLS.get(skill)(s, **args)
    wps, closed = [], False
    for w in plan.waypoints:
        closed = closed or w.label == "release"
        wps.append(Waypoint(w.q, CLOSED, w.duration, w.hold, w.label) if closed else w)
    return MotionPlan(plan.skill, tuple(wps))


# -- press ------------------------------------------------------------------------------------------

def _press_point(s: Skills, args: Args) -> tuple[np.ndarray, float, float, float]:
    """Top of the functional point (world), the hand's yaw, the stroke and the travel (scaled)."""
    obj = str(args["obj"])
    inst = s.world.object(obj)
    fp = CATALOG.get(inst.type_name).functional_point(args.get("point"))
    pos, rot = s.world.object_pos(obj), s.world.object_mat(obj)
    top = pos + rot @ (np.asarray(fp.pos) * inst.scale)
    travel = fp.travel * (inst.scale if fp.kind == "button" else 1.0)
    return top, s.natural_yaw(yaw_of(rot) + math.pi / 2), fp.stroke * inst.scale, travel


@_fault("press_light", ("press",), "press at most half the distance the button must travel")
def _press_light(s: Skills, skill: str, args: Args, rng: np.random.Generator) -> MotionPlan:
    _, _, stroke, travel = _press_point(s, args)
    return press(s, str(args["obj"]), args.get("point"), depth=-stroke + rng.uniform(0.0, 0.5) * travel)


@_fault("press_hover", ("press",), "stop 1.5-3 cm above the button")
def _press_hover(s: Skills, skill: str, args: Args, rng: np.random.Generator) -> MotionPlan:
    _, _, stroke, _ = _press_point(s, args)
    return press(s, str(args["obj"]), args.get("point"), depth=-stroke - rng.uniform(0.015, 0.03))


@_fault("press_miss", ("press",), "press 4-7 cm beside the button, as deep as a press")
def _press_miss(s: Skills, skill: str, args: Args, rng: np.random.Generator) -> MotionPlan:
    top, yaw, stroke, _ = _press_point(s, args)
    contact = top + _direction(rng) * rng.uniform(0.04, 0.07) + [0.0, 0.0, FINGER_REACH]
    bottom = contact - [0.0, 0.0, stroke + 0.004]
    bottom[2] = max(bottom[2], s.table_z + FINGER_REACH)
    wps = [Waypoint(s.q, CLOSED, 0.3, label="close")]
    wps += s.transit(wps[-1].q, contact + [0.0, 0.0, 0.06], yaw, CLOSED)
    wps += s.line(wps[-1].q, bottom, yaw, CLOSED, 0.08, "press")
    wps[-1] = Waypoint(wps[-1].q, CLOSED, wps[-1].duration, hold=0.3, label="press")
    wps += s.line(wps[-1].q, contact + [0.0, 0.0, 0.06], yaw, CLOSED, SLOW_SPEED, "release")
    return MotionPlan("press", tuple(wps))


# -- turn_and_place, move_line, shake --------------------------------------------------------------

@_fault("turn_short", ("turn_and_place", "turn_to_face"), "put the object down turned only 30-60% of the "
        "angle asked (or needed to face the robot)")
def _turn_short(s: Skills, skill: str, args: Args, rng: np.random.Generator) -> MotionPlan:
    share = rng.uniform(0.3, 0.6)
    if skill == "turn_to_face":
        return turned_to_face(s, **{**args, "share": share})
    return turn_and_place(s, **{**args, "turn": float(args["turn"]) * share})


@_fault("hang_short", ("hang",), "thread the loop only 20-50% of the way onto the hook before lowering and "
        "letting go: it comes down beside the hook's end")
def _hang_short(s: Skills, skill: str, args: Args, rng: np.random.Generator) -> MotionPlan:
    return hung(s, **{**args, "thread": rng.uniform(0.2, 0.5)})


@_fault("stop_short", ("move_line",), "stop 40-70% of the way along the line (a strike, pull or slide "
        "that never arrives)")
def _stop_short(s: Skills, skill: str, args: Args, rng: np.random.Generator) -> MotionPlan:
    start, _ = s.tcp()
    goal = np.asarray(args["pos"], float)
    return move_line(s, **{**args, "pos": start + rng.uniform(0.4, 0.7) * (goal - start)})


@_fault("pull_short", ("open_drawer", "close_drawer"), "slide the drawer only 30-60% of the way asked")
def _pull_short(s: Skills, skill: str, args: Args, rng: np.random.Generator) -> MotionPlan:
    obj, point = str(args["obj"]), args.get("point")
    now = opening(s.world, obj, point)
    to = goal_opening(s.world, obj, skill, point, args.get("distance"))
    return slide(s, obj, now + rng.uniform(0.3, 0.6) * (to - now), point, skill)


@_fault("shake_weak", ("shake",), "shake once, at 20-40% of the amplitude asked")
def _shake_weak(s: Skills, skill: str, args: Args, rng: np.random.Generator) -> MotionPlan:
    amplitude = float(args.get("amplitude", 0.04)) * rng.uniform(0.2, 0.4)
    return shake(s, **{**args, "amplitude": amplitude, "cycles": 1})


# -- both -------------------------------------------------------------------------------------------

@_fault("wrong_object", ("pick_and_place", "press"), "do the call on the nearest other object that "
        "allows it (grasp or press)")
def _wrong_object(s: Skills, skill: str, args: Args, rng: np.random.Generator) -> MotionPlan | None:
    if skill == "press":
        others = _others(s, args, lambda n: _pressable(s, n))
        return press(s, others[0]) if others else None
    others = _others(s, args, lambda n: _graspable(s, n))
    if not others:
        return None
    plan, offset = _pick(s, others[0], None)
    return _release(s, _lower(s, plan, _surface(s, args), offset))


@_fault("knock_over", ("pick_and_place", "press"), "after the call, sweep the hand through its object "
        "2-5 cm above the table, 10-15 cm along a random direction", after=True)
def _knock_over(s: Skills, skill: str, args: Args, rng: np.random.Generator) -> MotionPlan:
    return push(s, str(args["obj"]), tuple(_direction(rng)[:2]), rng.uniform(0.10, 0.15),
                height=rng.uniform(0.02, 0.05))


@_fault("grasp_miss", ("grasp", "pick_and_place"), "close the hand 4-6 cm beside the grasp, then go on "
        "as planned with an empty hand")
def _grasp_miss(s: Skills, skill: str, args: Args, rng: np.random.Generator) -> MotionPlan:
    choice, _ = s.choose_grasp(str(args["obj"]), args.get("grasp_name"))
    pos = choice.pos + _direction(rng) * rng.uniform(0.04, 0.06)
    pos[2] += 0.03  # above the table and the object's side: a miss, not a collision
    wps = s.transit(s.q, pos + [0.0, 0.0, APPROACH], choice.yaw, OPEN)
    wps += s.line(wps[-1].q, pos, choice.yaw, OPEN, SLOW_SPEED, "descend")
    wps.append(Waypoint(wps[-1].q, CLOSED, 0.3, hold=0.5, label="close"))
    plan = MotionPlan(skill, tuple(wps))
    if skill == "grasp":
        return plan
    with s.after(plan):
        plan = plan + lift(s)
    return _release(s, _lower(s, plan, _surface(s, args), s.world.object_pos(str(args["obj"])) - choice.pos))
