"""The annotated object catalog: object types, their metadata, and queries over them."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field

from vcage.assets.annotations import Annotations, FunctionalPoint, Grasp, Placement
from vcage.assets.parts import RGBA, PartBuilder
from vcage.errors import CatalogError
from vcage.registry import Registry

FACE_KINDS = frozenset({"display", "outlet"})  # functional points that are meant to face someone

Builder = Callable[[PartBuilder], None]


@dataclass(frozen=True)
class ObjectType:
    """One kind of object: how to build it and what a planner, skill or critic may know about it.

    ``size`` is the full extent (x, y, z) in metres at scale 1 with the origin at the centre of the
    resting face. ``colors`` maps variant names to RGBA; the first is the default.
    ``fixed`` objects are welded to their support (no free joint), e.g. a wall switch plate.
    ``any_face``: a cube whose faces are all alike (a block, a die, a Rubik's cube); it rests on
    whichever face is down and carries what is put on whichever face is up (its placement ``pos`` is
    the top face's centre).
    ``top_relief``: how far (RMS, metres) its top, seen from straight above as it stands on its base
    at scale 1, lies from the plane that fits it best; declared for a domed top (a mouse), so that a
    critic can tell the flat underside of one lying on its back without having seen it upright
    (0: not declared). ``tests/critics`` holds each declared value to the rendered model.
    """

    name: str
    category: str
    description: str
    size: tuple[float, float, float]
    mass: float
    colors: Mapping[str, RGBA]
    build: Builder = field(repr=False, compare=False)
    tags: frozenset[str] = frozenset()
    scale_range: tuple[float, float] = (0.9, 1.1)
    annotations: Annotations = Annotations()
    fixed: bool = False
    any_face: bool = False
    top_relief: float = 0.0

    def __post_init__(self) -> None:
        if not self.colors:
            raise CatalogError(f"object type {self.name!r} needs at least one colour variant")
        lo, hi = self.scale_range
        if not 0 < lo <= 1.0 <= hi:
            raise CatalogError(f"object type {self.name!r}: scale_range {self.scale_range} must contain 1")

    @property
    def grasps(self) -> tuple[Grasp, ...]:
        return self.annotations.grasps

    @property
    def placements(self) -> tuple[Placement, ...]:
        return self.annotations.placements

    @property
    def functional_points(self) -> tuple[FunctionalPoint, ...]:
        return self.annotations.functional_points

    def placement(self, name: str | None = None) -> Placement:
        return _find(self.placements, name, f"{self.name} placement")

    def functional_point(self, name: str | None = None) -> FunctionalPoint:
        return _find(self.functional_points, name, f"{self.name} functional point")

    @property
    def face(self) -> FunctionalPoint | None:
        """The functional point that is turned towards someone (a board's code, a fan's outlet): the
        first of a kind in :data:`FACE_KINDS` that points sideways; None if it has none."""
        return next((p for p in self.functional_points
                     if p.kind in FACE_KINDS and abs(p.direction[2]) < 0.5), None)

    def point_of_kind(self, kind: str, name: str | None = None) -> FunctionalPoint | None:
        """Its first functional point of ``kind`` (``name``: the one of that name); None if none."""
        return next((p for p in self.functional_points if p.kind == kind and name in (None, p.name)), None)

    @property
    def drawer_handles(self) -> tuple[FunctionalPoint, ...]:
        """The handles of its drawers: functional points of kind ``handle`` on a joint."""
        return tuple(p for p in self.functional_points if p.kind == "handle" and p.joint)

    def drawer_handle(self, name: str | None = None) -> FunctionalPoint | None:
        """Its drawer handle ``name`` (None: the first); None if it has no such handle."""
        return next((p for p in self.drawer_handles if name is None or p.name == name), None)

    def color(self, variant: str | None = None) -> RGBA:
        if variant is None:
            return next(iter(self.colors.values()))
        try:
            return self.colors[variant]
        except KeyError:
            raise CatalogError(
                f"{self.name} has no colour {variant!r}; variants: {sorted(self.colors)}"
            ) from None

    @property
    def footprint_radius(self) -> float:
        return 0.5 * (self.size[0] ** 2 + self.size[1] ** 2) ** 0.5


def _find(items: Iterable, name: str | None, what: str):  # type: ignore[no-untyped-def]
    items = tuple(items)
    if not items:
        raise CatalogError(f"{what}: none annotated")
    if name is None:
        return items[0]
    for item in items:
        if item.name == name:
            return item
    raise CatalogError(f"unknown {what} {name!r}; valid: {[i.name for i in items]}")


class Catalog(Registry[ObjectType]):
    """The object types by name: a :class:`Registry` (unknown or duplicate names raise
    :class:`CatalogError` listing the valid ones) with queries by category and tag.

    Every query answers in name order. The built-in types are added when ``vcage.assets`` is
    imported (its ``__init__`` imports :mod:`vcage.assets.objects`), so this module needs no
    import of its own to be full.
    """

    def __init__(self) -> None:
        super().__init__("object type", error=CatalogError)

    def add_type(self, obj: ObjectType) -> ObjectType:
        """Add ``obj`` under its own name."""
        return self.add(obj.name, obj)

    def categories(self) -> list[str]:
        return sorted({o.category for o in self.values()})

    def by_category(self, category: str) -> list[ObjectType]:
        found = [o for o in self.values() if o.category == category]
        if not found:
            raise CatalogError(f"unknown category {category!r}; valid: {', '.join(self.categories())}")
        return found

    def by_tag(self, tag: str) -> list[ObjectType]:
        return [o for o in self.values() if tag in o.tags]

    def names_where(self, test: Callable[[ObjectType], object]) -> list[str]:
        """The names of the types that pass ``test`` (for messages that say which types would do)."""
        return [o.name for o in self.values() if test(o)]

    def with_point(self, kind: str) -> list[str]:
        """The names of the types with a functional point of ``kind`` (a loop, a hook)."""
        return self.names_where(lambda o: o.point_of_kind(kind) is not None)


CATALOG = Catalog()
