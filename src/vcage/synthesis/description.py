"""``D_scene``: the scene a prompt asks for, as validated data.

Objects (catalog types, unique names) and spatial relations between them, plus the free text an
image model is prompted with. Relations, as the robot sees the table (it stands at x = 0 facing +x,
+y is its left): ``on`` / ``inside`` (``a`` rests on / in ``b``'s placement annotation),
``left_of`` / ``right_of`` (``a.y`` beyond ``b.y`` by at least ``distance``), ``in_front_of`` /
``behind`` (``a`` nearer to / further from the robot than ``b`` by ``distance``), ``near`` (origins
within ``distance`` plus both footprint radii) and ``aligned`` (in one row across the table: equal x
within 1 cm).

Validation refuses what no arrangement could satisfy: unknown names, relations of an object to
itself, two supports for one object, supports that form a cycle or do not fit, opposite relations
of one pair, cycles of an order relation, and objects that cannot fit on the table.
"""

from __future__ import annotations

import math
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from vcage.assets.catalog import CATALOG
from vcage.scene.layout import IN_FILL, ON_OVERHANG
from vcage.scene.spec import TableSpec
from vcage.synthesis.errors import SceneDescriptionError

RelationKind = Literal["on", "inside", "left_of", "right_of", "in_front_of", "behind", "near", "aligned"]
SUPPORTS = ("on", "inside")
OPPOSITE = {"left_of": "right_of", "right_of": "left_of", "in_front_of": "behind", "behind": "in_front_of"}
DEFAULT_GAP = 0.03  # default distance of an order relation (m)
NEAR_GAP = 0.08  # default slack of ``near`` beyond touching footprints (m)
PACKING = 0.45  # share of the usable table area footprints may cover before a description is refused
MAX_OBJECTS = 12


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class SceneObject(_Strict):
    name: str = Field(min_length=1, max_length=40, pattern=r"^[A-Za-z0-9_]+$")
    type: str
    color: str | None = None
    scale: float = Field(default=1.0, ge=0.7, le=1.3)

    @field_validator("type")
    @classmethod
    def _known_type(cls, v: str) -> str:
        if v not in CATALOG:
            raise ValueError(f"unknown object type {v!r}; catalog types: {', '.join(CATALOG.names())}")
        if CATALOG.get(v).fixed:
            raise ValueError(f"{v} is fixed to its support and cannot be arranged")
        return v

    @model_validator(mode="after")
    def _known_color(self) -> SceneObject:
        colors = CATALOG.get(self.type).colors
        if self.color is not None and self.color not in colors:
            raise ValueError(f"{self.type} has no colour {self.color!r}; variants: {sorted(colors)}")
        return self

    def half_extents(self) -> tuple[float, float]:
        sx, sy, _ = CATALOG.get(self.type).size
        return sx * self.scale / 2, sy * self.scale / 2

    @property
    def radius(self) -> float:
        hx, hy = self.half_extents()
        return math.hypot(hx, hy)


class SceneRelation(_Strict):
    kind: RelationKind
    a: str
    b: str
    distance: float | None = Field(default=None, ge=0.0, le=0.5)

    @model_validator(mode="after")
    def _not_self(self) -> SceneRelation:
        if self.a == self.b:
            raise ValueError(f"relation {self.kind}({self.a}, {self.b}) relates an object to itself")
        return self

    @property
    def gap(self) -> float:
        if self.distance is not None:
            return self.distance
        return NEAR_GAP if self.kind == "near" else DEFAULT_GAP

    def __str__(self) -> str:
        return f"{self.kind}({self.a}, {self.b})"


class SceneDescription(_Strict):
    prompt: str = Field(min_length=1)
    objects: tuple[SceneObject, ...] = Field(min_length=1, max_length=MAX_OBJECTS)
    relations: tuple[SceneRelation, ...] = ()
    text: str = Field(min_length=3, max_length=2000)  # what an image model is asked to show

    @model_validator(mode="after")
    def _consistent(self) -> SceneDescription:
        names = [o.name for o in self.objects]
        if len(set(names)) != len(names):
            raise ValueError(f"object names must be unique: {names}")
        for r in self.relations:
            for n in (r.a, r.b):
                if n not in names:
                    raise ValueError(f"relation {r} names unknown object {n!r}; objects: {names}")
        self._check_supports()
        self._check_orders()
        self._check_fit(TableSpec())
        return self

    # -- supports ------------------------------------------------------------------------------
    def support_of(self, name: str) -> SceneRelation | None:
        return next((r for r in self.relations if r.kind in SUPPORTS and r.a == name), None)

    def object(self, name: str) -> SceneObject:
        return next(o for o in self.objects if o.name == name)

    def _check_supports(self) -> None:
        seen: dict[str, SceneRelation] = {}
        for r in self.relations:
            if r.kind not in SUPPORTS:
                continue
            if r.a in seen:
                raise ValueError(f"{r.a!r} has two supports: {seen[r.a]} and {r}; an object rests on one")
            seen[r.a] = r
            child, host = self.object(r.a), self.object(r.b)
            kind = "on" if r.kind == "on" else "in"
            places = [p for p in CATALOG.get(host.type).placements if p.kind == kind]
            if not places:
                what = "surface to stand on" if kind == "on" else "room to hold objects inside"
                raise ValueError(f"{r}: {host.type} has no {what}")
            ours = sorted(2 * h for h in child.half_extents())
            theirs = sorted(s * host.scale for s in CATALOG.get(host.type).size[:2])
            limit = ON_OVERHANG if kind == "on" else IN_FILL
            if ours[0] > limit * theirs[0] or ours[1] > limit * theirs[1]:
                raise ValueError(f"{r}: {child.type} ({ours[0]:.2f} x {ours[1]:.2f} m) is too large for "
                                 f"{host.type} ({theirs[0]:.2f} x {theirs[1]:.2f} m)")
        for start in seen:
            chain, cur = [start], start
            while cur in seen:
                cur = seen[cur].b
                if cur in chain:
                    raise ValueError(f"supports form a cycle: {' -> '.join([*chain, cur])}")
                chain.append(cur)

    # -- order relations -----------------------------------------------------------------------
    def _check_orders(self) -> None:
        edges: dict[str, set[tuple[str, str]]] = {"left_of": set(), "in_front_of": set()}
        pairs: dict[frozenset[str], SceneRelation] = {}
        for r in self.relations:
            if r.kind in OPPOSITE:
                key = "left_of" if r.kind in ("left_of", "right_of") else "in_front_of"
                edge = (r.a, r.b) if r.kind == key else (r.b, r.a)
                edges[key].add(edge)
            if r.kind in SUPPORTS or r.kind in OPPOSITE:
                other = pairs.get(frozenset((r.a, r.b)))
                if other is not None and r.kind in SUPPORTS and other.kind in SUPPORTS:
                    raise ValueError(f"relations contradict: {other} and {r}")
                if other is not None and r.kind in SUPPORTS and other.kind in OPPOSITE or (
                        other is not None and other.kind in SUPPORTS and r.kind in OPPOSITE):
                    raise ValueError(f"relations contradict: {other} and {r}: an object on or in another "
                                     "cannot also be beside it")
                pairs.setdefault(frozenset((r.a, r.b)), r)
        for key, es in edges.items():
            cycle = _cycle(es)
            if cycle:
                word = key.replace("_", " ")
                raise ValueError(f"relations contradict: {' -> '.join(cycle)} would each be {word} the next")

    # -- fit --------------------------------------------------------------------------------------
    def table_objects(self) -> list[SceneObject]:
        return [o for o in self.objects if self.support_of(o.name) is None]

    def _check_fit(self, table: TableSpec) -> None:
        usable = table.size[0] * table.size[1] * 0.5  # the half of the table the arm reaches
        area = sum(4 * math.prod(o.half_extents()) for o in self.table_objects())
        if area > PACKING * usable:
            raise ValueError(f"the objects standing on the table cover {area:.3f} m2, more than "
                             f"{PACKING:.0%} of the {usable:.2f} m2 the arm reaches: use fewer or smaller "
                             "objects, or put some on or inside others")
        for key, axis, span in (("left_of", 1, table.size[1]), ("in_front_of", 0, table.size[0] / 2)):
            need = self._longest_chain(key, axis)
            if need > span:
                word = key.replace("_", " ")
                raise ValueError(f"a chain of objects each {word} the next needs {need:.2f} m, more than "
                                 f"the {span:.2f} m the table offers: shorten the chain or the distances")

    def _longest_chain(self, key: str, axis: int) -> float:
        """Length the longest chain of an order relation needs along ``axis`` (object widths + gaps)."""
        succ: dict[str, list[tuple[str, float]]] = {}
        for r in self.relations:
            if r.kind in OPPOSITE and (r.kind == key or OPPOSITE[r.kind] == key):
                a, b = (r.a, r.b) if r.kind == key else (r.b, r.a)
                succ.setdefault(a, []).append((b, r.gap))

        def width(n: str) -> float:
            return 2 * self.object(n).radius if axis == 1 else 2 * self.object(n).half_extents()[0]

        memo: dict[str, float] = {}

        def longest(n: str) -> float:
            if n not in memo:
                memo[n] = width(n) + max((g + longest(m) for m, g in succ.get(n, [])), default=0.0)
            return memo[n]

        return max((longest(n) for n in succ), default=0.0)


def _cycle(edges: set[tuple[str, str]]) -> list[str] | None:
    succ: dict[str, list[str]] = {}
    for a, b in sorted(edges):
        succ.setdefault(a, []).append(b)
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(n: str) -> list[str] | None:
        state[n] = 1
        stack.append(n)
        for m in succ.get(n, []):
            if state.get(m) == 1:
                return [*stack[stack.index(m):], m]
            if m not in state:
                found = visit(m)
                if found:
                    return found
        stack.pop()
        state[n] = 2
        return None

    for n in sorted(succ):
        if n not in state:
            found = visit(n)
            if found:
                return found
    return None


def describe_errors(exc: ValidationError) -> str:
    return "; ".join(f"{'.'.join(str(p) for p in e['loc']) or 'description'}: {e['msg']}"
                     for e in exc.errors()[:8])


def parse_description(data: object) -> SceneDescription:
    """A :class:`SceneDescription` from JSON-like data; refusals raise :class:`SceneDescriptionError`."""
    try:
        return SceneDescription.model_validate(data)
    except ValidationError as exc:
        raise SceneDescriptionError(f"the scene description is invalid: {describe_errors(exc)}") from None


def description_schema() -> dict[str, object]:
    return SceneDescription.model_json_schema()
