"""The scene for a whole plan: its objects placed context-aware in the work area, plus clutter.

Task objects go into :data:`WORK_AREA` (where the skills' experts are measured); distractors may
go anywhere within reach. Objects a subtask grasps keep their finger zones clear (see
:class:`~vcage.scene.layout.LayoutObject`); targets and pressed objects need none. Targets given
as positions (``xy`` arguments) become reserved zones, so clutter never occupies them.
"""

from __future__ import annotations

import math

import numpy as np

from vcage.assets.catalog import CATALOG
from vcage.config import Randomization
from vcage.errors import SceneError
from vcage.planning.schema import Plan, PlanObject
from vcage.scene.layout import (
    Distractors,
    LayoutObject,
    LayoutSpec,
    Region,
    Relation,
    ReservedZone,
    Support,
)
from vcage.scene.placement.geometry import carry_radius
from vcage.scene.randomize import environment, object_look
from vcage.synthesis.scene_file import PlacedObject, SynthesisRequest, SynthesizedScene, ground_plan

# x 0.45..0.70, y -0.3..0.3 (metres): reachable for every skill, and clear of the arm's home pose
# in the top view, so that the critic sees the objects after each subtask
WORK_AREA = Region((0.575, 0.0), (0.125, 0.3))
TARGET_ZONE = 0.05  # half size of the zone kept free around a position target
GRASPING_SKILLS = ("pick_and_place", "grasp")  # plan skills whose ``obj`` the fingers close on
DRAWER_SKILLS = ("open_drawer", "close_drawer")  # plan skills that slide ``obj``'s drawer
# An object whose drawer a plan slides turns its handle towards the robot, within this many radians,
# and stands far enough back in the work area that its drawer, pulled out, stays in it (clear of the
# arm's home pose in the top view, where the critic measures how far it is out)
DRAWER_YAW = 0.35
HANG_SKILLS = ("hang",)  # plan skills that hang ``obj`` on ``target``'s hook
# An object something is hung on turns its hook's free end towards the robot's right (-y), as
# hanging_mug's rack stands, within this many radians: the hand then brings the held object from
# the robot's side of the hook (a free end pointing away would need it to reach round the post)
HOOK_YAW = 0.6


def plan_layout(plan: Plan, rng: np.random.Generator, rand: Randomization, clutter: int = 0,
                work_area: Region = WORK_AREA, scene: SynthesizedScene | None = None) -> LayoutSpec:
    """The plan's layout; with a synthesized ``scene`` (its objects named as the plan's, see
    :func:`~vcage.synthesis.scene_file.ground_plan`) each object on the table starts at its pose
    there, jittered by ``rand`` like a task's nominal item, instead of anywhere in ``work_area``."""
    looks = {}
    for o in _largest_first(plan):
        scale, color, friction = object_look(o.type, rng, rand, (o.color,) if o.color else None)
        looks[o.name] = (o.scale if o.scale is not None else scale, color, friction)
    grasped = {str(st.args["obj"]) for st in plan.subtasks if st.skill in GRASPING_SKILLS}
    receives = _room_needed(plan, {name: look[0] for name, look in looks.items()})
    slides = _drawers_slid(plan, {name: look[0] for name, look in looks.items()})
    hangs = _hooks_used(plan, {name: look[0] for name, look in looks.items()})
    objects = []
    for o in _largest_first(plan):
        scale, color, friction = looks[o.name]
        support = Support(o.on) if o.on else Support()
        region, yaw = None if o.on else work_area, (-math.pi, math.pi)
        placed = scene.object(o.name) if scene is not None and not o.on else None
        if placed is not None:
            region, yaw = _nominal(placed, rand)
        elif o.name in slides and not o.on:
            region, yaw = _drawer_pose(o.type, scale, slides[o.name], work_area)
        elif o.name in hangs and not o.on:
            yaw = _hook_yaw(o.type)
        room, room_at = receives.get(o.name, (0.0, None))
        objects.append(LayoutObject(o.name, o.type, support=support, region=region, yaw=yaw, scale=scale,
                                    color=color, friction=friction, grasped=o.name in grasped,
                                    receives=room, receives_at=room_at, slides=slides.get(o.name, 0.0),
                                    hangs=hangs.get(o.name, 0.0)))
    relations = tuple(Relation(r.kind, r.a, r.b, r.distance) for r in plan.relations)
    reserved = tuple(
        ReservedZone(f"subtask{i}", Region((float(st.args["xy"][0]), float(st.args["xy"][1])),
                                           (TARGET_ZONE, TARGET_ZONE)))
        for i, st in enumerate(plan.subtasks) if st.args.get("xy") is not None)
    return LayoutSpec(objects=tuple(objects), relations=relations, reserved=reserved,
                      distractors=Distractors(clutter), **environment(rng, rand))


def episode_scene(plan: Plan, request: SynthesisRequest, seed: int) -> SynthesizedScene:
    """A scene synthesized afresh from ``request`` for the attempt of ``seed``, its objects named as
    ``plan``'s (grounded as :func:`~vcage.synthesis.scene_file.ground_plan` does). Raises
    :class:`~vcage.errors.SceneError` when the scene is not the one the plan was grounded on (other
    objects, colours or supports), and the synthesis' own errors when no scene came out."""
    from vcage.synthesis.driver import synthesized_scene

    grounded, scene = ground_plan(plan, synthesized_scene(request, seed))
    if grounded.objects != plan.objects:
        got = ", ".join(f"{o.name} ({o.type})" for o in grounded.objects)
        raise SceneError(f"the scene synthesized from {request.prompt!r} for seed {seed} holds {got}, not "
                         "the plan's objects; synthesis must give the same objects for every seed")
    return scene


def _room_needed(plan: Plan, scales: dict[str, float]) -> dict[str, tuple[float, str | None]]:
    """For each target something is put on or in: the room the hand needs there (the largest
    :func:`~vcage.scene.placement.geometry.carry_radius` of what goes there) and its placement."""
    types = {o.name: o.type for o in plan.objects}
    out: dict[str, tuple[float, str | None]] = {}
    for st in plan.subtasks:
        target = st.args.get("target")
        if st.skill != "pick_and_place" or target is None:
            continue
        held = str(st.args["obj"])
        room = carry_radius(types[held], scales[held])
        if room > out.get(str(target), (0.0, None))[0]:
            out[str(target)] = (room, st.args.get("placement"))
    return out


def _drawers_slid(plan: Plan, scales: dict[str, float]) -> dict[str, float]:
    """How far each object whose drawer a subtask slides will have it out at most (metres)."""
    types = {o.name: o.type for o in plan.objects}
    out: dict[str, float] = {}
    for st in plan.subtasks:
        if st.skill not in DRAWER_SKILLS:
            continue
        name = str(st.args["obj"])
        otype = CATALOG.get(types[name])
        handle = otype.drawer_handle(st.args.get("point")) or otype.drawer_handle()
        if handle is None:  # the plan's check refuses this; the skill would raise
            continue
        far = handle.stroke * scales[name] if st.args.get("distance") is None else float(st.args["distance"])
        out[name] = max(out.get(name, 0.0), far)
    return out


def _hooks_used(plan: Plan, scales: dict[str, float]) -> dict[str, float]:
    """For each object something is hung on: the room kept free at its hook's end (the largest
    :func:`~vcage.scene.placement.geometry.carry_radius` of what is hung there)."""
    types = {o.name: o.type for o in plan.objects}
    out: dict[str, float] = {}
    for st in plan.subtasks:
        if st.skill in HANG_SKILLS and isinstance(st.args.get("target"), str):
            held, host = str(st.args["obj"]), str(st.args["target"])
            out[host] = max(out.get(host, 0.0), carry_radius(types[held], scales[held]))
    return out


def _hook_yaw(type_: str) -> tuple[float, float]:
    """The yaw range of an object whose hook's free end turns towards the robot's right (-y)."""
    hook = CATALOG.get(type_).point_of_kind("hook")
    assert hook is not None  # the plan's check refuses a hang on an object without a hook
    free_end = math.atan2(-hook.direction[1], -hook.direction[0])  # in the object's frame
    facing = -math.pi / 2 - free_end
    return facing - HOOK_YAW, facing + HOOK_YAW


def _drawer_pose(type_: str, scale: float, out: float,
                 work_area: Region) -> tuple[Region, tuple[float, float]]:
    """The region and yaw range of an object whose drawer comes ``out`` metres towards the robot
    (-x): its handle faces the robot, and the drawer's front stays in ``work_area``."""
    otype = CATALOG.get(type_)
    handle = otype.drawer_handle()
    assert handle is not None  # only objects with a drawer get here
    way_out = math.atan2(handle.direction[1], handle.direction[0])  # in the object's frame
    facing = math.pi - way_out  # the yaw that turns the way out towards -x
    half_depth = otype.size[0 if abs(math.cos(way_out)) > 0.5 else 1] * scale / 2
    (x0, y0, x1, y1) = work_area.bounds
    lo = min(x0 + half_depth + out, x1)
    region = Region(((lo + x1) / 2, (y0 + y1) / 2), ((x1 - lo) / 2, (y1 - y0) / 2))
    return region, (facing - DRAWER_YAW, facing + DRAWER_YAW)


def _nominal(placed: PlacedObject, rand: Randomization) -> tuple[Region, tuple[float, float]]:
    """The region and yaw range of an object at a nominal pose, as :func:`tasks.items.task_layout`
    jitters its items."""
    if not rand.enabled:
        return Region((placed.x, placed.y)), (placed.yaw, placed.yaw)
    lo, hi = rand.object_xy.low, rand.object_xy.high
    mid = (lo + hi) / 2
    region = Region((placed.x + mid, placed.y + mid), ((hi - lo) / 2, (hi - lo) / 2))
    return region, (placed.yaw + rand.object_yaw.low, placed.yaw + rand.object_yaw.high)


def _largest_first(plan: Plan) -> list[PlanObject]:
    """Big footprints are the hardest to fit, so they are placed first (supports stay first)."""
    def area(o: PlanObject) -> float:
        sx, sy = CATALOG.get(o.type).size[:2]
        return sx * sy

    return sorted(plan.objects, key=lambda o: (o.on is not None, -area(o)))
