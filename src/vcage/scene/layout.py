"""Declarative scene layout: what goes where, before any pose is chosen.

A :class:`LayoutSpec` lists the objects of a scene, the support each one stands on (the table, or
a placement annotation of another object: on a pad, inside a basket, on a block), relations
between them, zones that must stay free, and distractors to add as clutter. A placement method
(:mod:`vcage.scene.placement`) turns it into a :class:`~vcage.scene.spec.SceneSpec` with poses.

:func:`validate` refuses impossible layouts before any sampling, naming the constraint.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

from vcage.assets.catalog import CATALOG
from vcage.errors import PlacementError
from vcage.scene.spec import TableSpec

RELATIONS = ("left_of", "right_of", "near", "far_from")
# An object may overhang an "on" support (a phone on its stand) but not dwarf it, and must fit an
# "in" support (a loaf in a basket) with some room to spare.
ON_OVERHANG = 2.0
IN_FILL = 0.9


@dataclass(frozen=True)
class Support:
    """What an object stands on: the table (``obj`` None) or ``obj``'s placement annotation."""

    obj: str | None = None
    placement: str | None = None

    @property
    def is_table(self) -> bool:
        return self.obj is None

    def label(self) -> str:
        return "table" if self.obj is None else f"{self.obj}:{self.placement or 'default'}"


TABLE = Support()


@dataclass(frozen=True)
class Region:
    """An axis-aligned box of table positions (world x, y) for an object's origin."""

    center: tuple[float, float]
    half: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        if min(self.half) < 0:
            raise PlacementError(f"region half extents {self.half} must be non-negative")

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        (cx, cy), (hx, hy) = self.center, self.half
        return cx - hx, cy - hy, cx + hx, cy + hy


@dataclass(frozen=True)
class LayoutObject:
    """One object to place. ``region`` confines its origin; ``yaw`` is the range yaw is drawn from.

    ``task`` objects are the ones a plan manipulates: distractors keep clear of them so that the
    gripper can approach, and tall distractors keep further away. ``grasped`` says whether the
    robot will grasp a task object: context placement then keeps the ground its open fingers
    sweep free (its finger zones); objects that are only targets or pressed need none.
    ``receives`` is the radius kept free around the centre of the placement region ``receives_at``
    (None: the first) of an object the robot will put something on or in: what the hand carries
    there, fingers included. ``slides`` is how far the object's drawer will come out: the ground
    in front of it, as wide as the object, and the hand's room at the handle at that opening, are
    kept free. ``hangs`` is the radius kept free around the free end of the object's hook (its
    functional point of kind ``hook``), where something will be hung: what hangs there and the hand
    that brings it.
    """

    name: str
    type: str
    support: Support = TABLE
    region: Region | None = None
    yaw: tuple[float, float] = (-math.pi, math.pi)
    scale: float = 1.0
    color: str | None = None
    friction: float = 1.0
    task: bool = True
    grasped: bool = True
    receives: float = 0.0
    receives_at: str | None = None
    slides: float = 0.0
    hangs: float = 0.0

    def __post_init__(self) -> None:
        if self.yaw[0] > self.yaw[1]:
            raise PlacementError(f"object {self.name!r}: yaw range {self.yaw} is empty")


@dataclass(frozen=True)
class Relation:
    """``a`` relative to ``b``: left_of/right_of as seen from the robot (+y is left) by at least
    ``distance``, or ``near`` (within) / ``far_from`` (beyond) ``distance`` between origins."""

    kind: str
    a: str
    b: str
    distance: float = 0.05

    def __post_init__(self) -> None:
        if self.kind not in RELATIONS:
            raise PlacementError(f"unknown relation {self.kind!r}; valid: {', '.join(RELATIONS)}")
        if self.distance < 0:
            raise PlacementError(f"relation {self.kind}({self.a}, {self.b}): distance must be >= 0")
        if self.a == self.b:
            raise PlacementError(f"relation {self.kind}({self.a}, {self.b}) relates an object to itself")


@dataclass(frozen=True)
class ReservedZone:
    """A table region that must stay free of objects (e.g. where a subtask will put something)."""

    name: str
    region: Region


@dataclass(frozen=True)
class Distractors:
    """``count`` clutter objects drawn from the catalog (optionally by category or tag)."""

    count: int = 0
    categories: tuple[str, ...] = ()
    tags: tuple[str, ...] = ()
    exclude: tuple[str, ...] = ()  # types never drawn (the task's own types are always excluded)
    max_size: float = 0.16  # largest footprint side of a drawn type, metres

    def __post_init__(self) -> None:
        if self.count < 0:
            raise PlacementError(f"distractor count {self.count} must be >= 0")


@dataclass(frozen=True)
class LayoutSpec:
    objects: tuple[LayoutObject, ...] = ()
    relations: tuple[Relation, ...] = ()
    reserved: tuple[ReservedZone, ...] = ()
    distractors: Distractors = field(default_factory=Distractors)
    table: TableSpec = field(default_factory=TableSpec)
    light: float = 0.8
    camera_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def object(self, name: str) -> LayoutObject:
        for obj in self.objects:
            if obj.name == name:
                return obj
        raise PlacementError(f"no object {name!r} in the layout; objects: {[o.name for o in self.objects]}")

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def validate(layout: LayoutSpec) -> None:
    """Refuse a layout no placement could satisfy, saying which constraint is impossible."""
    names = [o.name for o in layout.objects]
    if len(set(names)) != len(names):
        raise PlacementError(f"object names must be unique: {names}")
    for obj in layout.objects:
        CATALOG.get(obj.type)  # unknown types list the valid ones
        _check_support(layout, obj)
        if obj.region is not None and obj.support.is_table:
            _check_region_on_table(obj, layout.table)
    _check_relations(layout)
    _check_reserved(layout)


def _check_support(layout: LayoutSpec, obj: LayoutObject) -> None:
    if obj.support.is_table:
        return
    assert obj.support.obj is not None
    if obj.support.obj == obj.name:
        raise PlacementError(f"object {obj.name!r} cannot stand on itself")
    host = layout.object(obj.support.obj)
    host_type = CATALOG.get(host.type)
    place = host_type.placement(obj.support.placement)
    size = sorted(CATALOG.get(obj.type).size[:2])
    host_size = sorted(host_type.size[:2])
    ours = [s * obj.scale for s in size]
    theirs = [s * host.scale for s in host_size]
    limit = ON_OVERHANG if place.kind == "on" else IN_FILL
    if ours[0] > limit * theirs[0] or ours[1] > limit * theirs[1]:
        word = "on" if place.kind == "on" else "inside"
        raise PlacementError(
            f"object {obj.name!r} ({ours[0]:.3f} x {ours[1]:.3f} m) is too large to stand {word} "
            f"{host.name!r} ({theirs[0]:.3f} x {theirs[1]:.3f} m): choose a larger support or a "
            "smaller object")
    seen = {obj.name}
    cur = host
    while not cur.support.is_table:
        if cur.name in seen:
            raise PlacementError(f"supports form a cycle through {sorted(seen)}")
        seen.add(cur.name)
        assert cur.support.obj is not None
        cur = layout.object(cur.support.obj)


def _check_region_on_table(obj: LayoutObject, table: TableSpec) -> None:
    assert obj.region is not None
    x0, y0, x1, y1 = obj.region.bounds
    (tx0, tx1), (ty0, ty1) = table.x_range, table.y_range
    if x1 < tx0 or x0 > tx1 or y1 < ty0 or y0 > ty1:
        raise PlacementError(f"object {obj.name!r}: region {obj.region.bounds} lies off the table "
                             f"(x {table.x_range}, y {table.y_range})")


def _check_relations(layout: LayoutSpec) -> None:
    names = {o.name for o in layout.objects}
    by_pair: dict[tuple[str, str], list[Relation]] = {}
    for rel in layout.relations:
        for n in (rel.a, rel.b):
            if n not in names:
                raise PlacementError(f"relation {rel.kind}({rel.a}, {rel.b}) names unknown object "
                                     f"{n!r}; objects: {sorted(names)}")
        key = (rel.a, rel.b) if rel.a < rel.b else (rel.b, rel.a)
        by_pair.setdefault(key, []).append(rel)
    for (a, b), rels in by_pair.items():
        sides = set()
        near, far = math.inf, 0.0
        for rel in rels:
            if rel.kind in ("left_of", "right_of"):
                flip = rel.a != a
                sides.add(rel.kind if not flip else ("right_of" if rel.kind == "left_of" else "left_of"))
            elif rel.kind == "near":
                near = min(near, rel.distance)
            else:
                far = max(far, rel.distance)
        if len(sides) > 1:
            raise PlacementError(f"relations contradict: {a!r} cannot be both left_of and right_of {b!r}")
        if far >= near:
            raise PlacementError(f"relations contradict: {a!r} and {b!r} must be within {near} m and "
                                 f"beyond {far} m of each other")
    relation_order(layout)  # refuses cycles


def relation_order(layout: LayoutSpec) -> list[str]:
    """Object names so that every support and every relation's ``b`` comes before its dependents.

    Within those constraints the declared order is kept. A cycle is refused.
    """
    deps: dict[str, set[str]] = {o.name: set() for o in layout.objects}
    for o in layout.objects:
        if o.support.obj is not None:
            deps[o.name].add(o.support.obj)
    for rel in layout.relations:
        deps[rel.a].add(rel.b)
    order: list[str] = []
    pending = [o.name for o in layout.objects]
    while pending:
        ready = [n for n in pending if deps[n] <= set(order)]
        if not ready:
            raise PlacementError(f"relations and supports form a cycle among {pending}")
        order.append(ready[0])
        pending.remove(ready[0])
    return order


def _check_reserved(layout: LayoutSpec) -> None:
    if not layout.reserved:
        return
    from shapely.geometry import box
    from shapely.ops import unary_union

    (tx0, tx1), (ty0, ty1) = layout.table.x_range, layout.table.y_range
    table = box(tx0, ty0, tx1, ty1)
    blocked = unary_union([box(*z.region.bounds) for z in layout.reserved])
    free = table.difference(blocked).area
    smallest = min((math.prod(CATALOG.get(o.type).size[:2]) * o.scale**2
                    for o in layout.objects if o.support.is_table), default=0.0)
    if free <= max(smallest, 1e-6):
        names = ", ".join(z.name for z in layout.reserved)
        raise PlacementError(
            f"reserved zones ({names}) cover {100 * (1 - free / table.area):.0f}% of the table, "
            "leaving no room for the objects: shrink the zones")
