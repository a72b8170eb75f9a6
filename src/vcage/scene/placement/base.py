"""The placement interface every method shares: a layout in, a posed scene and statistics out.

Subclasses implement :meth:`Placer._place_one`, returning an origin and yaw for one object (or
None when it does not fit). The base class validates the layout, draws distractors, orders the
objects (supports and relation targets first; distractors largest first), turns poses on
supports into world poses, and times every placement.
"""

from __future__ import annotations

import math
import time
from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import shapely

from vcage.assets.catalog import CATALOG, ObjectType
from vcage.config import from_fields
from vcage.errors import PlacementError
from vcage.registry import Registry
from vcage.scene.layout import LayoutObject, LayoutSpec, relation_order, validate
from vcage.scene.placement.geometry import footprint, to_world
from vcage.scene.placement.reach import ReachMap
from vcage.scene.spec import ObjectSpec, SceneSpec


@dataclass(frozen=True)
class PlacementConfig:
    margin: float = 0.01  # gap kept between any two footprints (m)
    task_clearance: float = 0.04  # distractors keep this far from task objects: room for fingers
    tall_clearance: float = 0.08  # ... and tall distractors this far: they would block the approach
    tall_height: float = 0.12  # objects taller than this count as tall (m)
    edge_margin: float = 0.02  # footprints stay this far inside the table's edge
    base_keepout: float = 0.2  # radius around the robot's base axis kept free (m)
    reach_distractors: bool = True  # distractors too stay within the arm's top-down reach
    yaw_tries: int = 4  # yaws tried before an object counts as not fitting
    max_backtracks: int = 10  # distractors re-placed before giving up
    rejection_tries: int = 5000  # the rejection baseline's tries per object (robosuite's default)
    drop: float = 0.002  # objects start this far above their support, so they never start in it
    # Keep every footprint out of the ground the open fingers sweep to grasp a task object (context
    # placement), with this much slack around the fingers' boxes.
    finger_zones: bool = True
    finger_slack: float = 0.005

    def __post_init__(self) -> None:
        for name in ("margin", "task_clearance", "tall_clearance", "edge_margin", "base_keepout",
                     "drop", "finger_slack"):
            if getattr(self, name) < 0:
                raise PlacementError(f"placement config {name} must be >= 0")
        if self.yaw_tries < 1 or self.rejection_tries < 1 or self.max_backtracks < 0:
            raise PlacementError("placement config: yaw_tries and rejection_tries must be >= 1, "
                                 "max_backtracks >= 0")

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> PlacementConfig:
        """Read a config. A complete one stored before finger zones existed (it has every field of
        then, not ``finger_zones``) placed without them and keeps doing so, so its runs reproduce."""
        if isinstance(data, dict) and set(_FIELDS_BEFORE_FINGER_ZONES) <= set(data) \
                and "finger_zones" not in data:
            data = {**data, "finger_zones": False}
        return from_fields(cls, data)


_FIELDS_BEFORE_FINGER_ZONES = ("margin", "task_clearance", "tall_clearance", "tall_height", "edge_margin",
                               "base_keepout", "reach_distractors", "yaw_tries", "max_backtracks",
                               "rejection_tries", "drop")


@dataclass
class PlacementStats:
    method: str
    seconds: list[float] = field(default_factory=list)  # wall time of each placed object
    backtracks: int = 0
    coverage: float = 0.0  # share of the table top covered by footprints at the end

    @property
    def placed(self) -> int:
        return len(self.seconds)


@dataclass(frozen=True)
class PlacementResult:
    scene: SceneSpec
    stats: PlacementStats


@dataclass(frozen=True)
class Pose:
    xy: tuple[float, float]
    yaw: float


class Placer(ABC):
    """Places a :class:`LayoutSpec`'s objects one at a time."""

    name: str = ""

    def __init__(self, config: PlacementConfig | None = None, reach: ReachMap | None = None) -> None:
        self.config = config or PlacementConfig()
        self.reach = reach

    # -- the interface --------------------------------------------------------------------------
    def place(self, layout: LayoutSpec, rng: np.random.Generator) -> PlacementResult:
        validate(layout)
        objects = [layout.object(n) for n in relation_order(layout)]
        objects += draw_distractors(layout, rng)
        self.begin(layout)
        stats = PlacementStats(self.name)
        poses = self.place_all(objects, rng, stats)
        stats.coverage = table_coverage(layout, objects, poses)
        specs = self.to_specs(layout, objects, poses)
        return PlacementResult(SceneSpec(objects=tuple(specs), table=layout.table, light=layout.light,
                                         camera_offset=layout.camera_offset), stats)

    def place_all(self, objects: list[LayoutObject], rng: np.random.Generator,
                  stats: PlacementStats) -> dict[str, Pose]:
        """Place in order; a method may override this to backtrack."""
        poses: dict[str, Pose] = {}
        for obj in objects:
            t0 = time.perf_counter()
            pose = self._place_one(obj, poses, rng)
            if pose is None:
                raise self.failure(obj, poses)
            poses[obj.name] = pose
            stats.seconds.append(time.perf_counter() - t0)
        return poses

    @abstractmethod
    def begin(self, layout: LayoutSpec) -> None:
        """Reset per-scene state before the first object."""

    @abstractmethod
    def _place_one(self, obj: LayoutObject, poses: dict[str, Pose],
                   rng: np.random.Generator) -> Pose | None:
        """A pose for ``obj`` given those already placed, or None if it does not fit."""

    def failure(self, obj: LayoutObject, poses: dict[str, Pose]) -> PlacementError:
        return PlacementError(f"{self.name} placement could not place {obj.name!r} ({obj.type}) on "
                              f"{obj.support.label()} after {len(poses)} objects")

    # -- shared helpers ---------------------------------------------------------------------------
    def to_specs(self, layout: LayoutSpec, objects: list[LayoutObject],
                 poses: dict[str, Pose]) -> list[ObjectSpec]:
        specs: dict[str, ObjectSpec] = {}
        rest: dict[str, float] = {}  # height each object's origin rests at
        for obj in objects:
            pose = poses[obj.name]
            if obj.support.is_table:
                rest[obj.name] = layout.table.height
            else:
                assert obj.support.obj is not None
                host = specs[obj.support.obj]
                place = CATALOG.get(host.type).placement(obj.support.placement)
                rest[obj.name] = rest[host.name] + place.pos[2] * host.scale
            z = rest[obj.name] + self.config.drop
            specs[obj.name] = ObjectSpec(obj.name, obj.type, pose.xy, pose.yaw, obj.scale, obj.color,
                                         obj.friction, z)
        return list(specs.values())


def support_frame(obj: LayoutObject, poses: dict[str, Pose],
                  objects: dict[str, LayoutObject]) -> tuple[np.ndarray, float, np.ndarray]:
    """World centre (x, y), yaw and half extents of the placement region ``obj`` stands on."""
    assert obj.support.obj is not None
    host = objects[obj.support.obj]
    hp = poses[host.name]
    place = CATALOG.get(host.type).placement(obj.support.placement)
    center = to_world(hp.xy, hp.yaw, np.asarray(place.pos[:2]) * host.scale)
    return center, hp.yaw, np.asarray(place.half_size) * host.scale


def table_coverage(layout: LayoutSpec, objects: list[LayoutObject], poses: dict[str, Pose]) -> float:
    """Share of the table top covered by the footprints of the objects standing on it."""
    (x0, x1), (y0, y1) = layout.table.x_range, layout.table.y_range
    table = shapely.box(x0, y0, x1, y1)
    shapes = [footprint(o.type, o.scale, poses[o.name].yaw, poses[o.name].xy)
              for o in objects if o.support.is_table]
    if not shapes:
        return 0.0
    return float(shapely.union_all(shapes).intersection(table).area / table.area)


def height(obj: LayoutObject) -> float:
    return CATALOG.get(obj.type).size[2] * obj.scale


def draw_distractors(layout: LayoutSpec, rng: np.random.Generator) -> list[LayoutObject]:
    """Clutter objects for the layout, largest first (they are the hardest to fit)."""
    spec = layout.distractors
    if spec.count == 0:
        return []
    own = {o.type for o in layout.objects}
    pool = [t for t in CATALOG.values() if _eligible(t, spec.categories, spec.tags, spec.max_size)
            and t.name not in own and t.name not in spec.exclude]
    if not pool:
        raise PlacementError(f"no catalog type fits the distractor filter (categories "
                             f"{spec.categories}, tags {spec.tags}, max_size {spec.max_size})")
    drawn = []
    taken = {o.name for o in layout.objects}
    for i in range(spec.count):
        otype = pool[int(rng.integers(len(pool)))]
        lo, hi = otype.scale_range
        name = f"clutter{i}_{otype.name}"
        while name in taken:
            name += "_"
        taken.add(name)
        colors = list(otype.colors)
        drawn.append(LayoutObject(name, otype.name, scale=float(rng.uniform(lo, hi)),
                                  color=colors[int(rng.integers(len(colors)))], task=False))
    drawn.sort(key=lambda o: -math.prod(CATALOG.get(o.type).size[:2]) * o.scale**2)
    return drawn


def _eligible(t: ObjectType, categories: tuple[str, ...], tags: tuple[str, ...], max_size: float) -> bool:
    if t.fixed or max(t.size[:2]) * t.scale_range[1] > max_size:
        return False
    if categories and t.category not in categories:
        return False
    return not tags or bool(t.tags & set(tags))


PLACERS: Registry[type[Placer]] = Registry("placement method")
