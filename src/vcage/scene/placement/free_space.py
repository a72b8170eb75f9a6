"""The prohibited-region map of one support surface, updated after every placement.

A :class:`SurfaceMap` holds the surface's domain for object origins (the table, or a placement
annotation's region), the footprints already on it, and fixed prohibited regions (the robot base,
reserved zones). :meth:`SurfaceMap.free` returns the origins at which a new footprint touches
none of them: the domain minus the configuration-space obstacle of every prohibited region for
that footprint. Sampling from it never needs blind rejection.

An object the robot will grasp also carries *finger zones* (:func:`.geometry.grasp_zone`): the
ground its open fingers sweep on the way down to each of its grasps. No footprint may lie in
another object's zone, so a neighbour never blocks a grasp; zones may overlap (the fingers go down
one at a time).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import shapely
from shapely.geometry import Polygon
from shapely.geometry.base import BaseGeometry

from vcage.scene.placement.geometry import minkowski_cobstacle


@dataclass(frozen=True)
class Occupant:
    """A footprint on the surface; ``task`` and ``tall`` decide the clearance others keep;
    ``zone`` is where the fingers go down to grasp it (convex pieces; empty: it is not grasped)."""

    name: str
    shape: Polygon
    task: bool = False
    tall: bool = False
    zone: tuple[Polygon, ...] = ()


# (occupant, new object's task flag, new object's tall flag) -> extra clearance in metres
Clearance = Callable[[Occupant, bool, bool], float]


class SurfaceMap:
    def __init__(self, label: str, surface: Polygon, usable: BaseGeometry | None = None) -> None:
        self.label = label
        self.surface = surface  # the physical surface (table top, a placement region)
        self.usable = surface if usable is None else usable  # the part objects may use (reach)
        self.occupants: dict[str, Occupant] = {}
        self.fixed: list[tuple[str, Polygon]] = []  # keep-outs that apply to every object

    def forbid(self, name: str, region: Polygon) -> None:
        self.fixed.append((name, region))

    def add(self, occupant: Occupant) -> None:
        self.occupants[occupant.name] = occupant

    def remove(self, name: str) -> None:
        del self.occupants[name]

    def free(self, shape: Polygon, task: bool, tall: bool, clearance: Clearance,
             domain: BaseGeometry, zone: tuple[Polygon, ...] = ()) -> BaseGeometry:
        """Origins in ``domain`` where ``shape`` (a footprint about the origin, already grown by
        the common margin) touches no occupant and no keep-out, and where no occupant's finger
        zone holds ``shape`` nor ``zone`` (the new object's, about its origin) any occupant."""
        obstacles = [minkowski_cobstacle(region, shape) for _, region in self.fixed]
        for occ in self.occupants.values():
            extra = clearance(occ, task, tall)
            grown = occ.shape if extra <= 0 else occ.shape.buffer(extra, join_style="mitre")
            obstacles.append(minkowski_cobstacle(grown, shape))
            obstacles.extend(minkowski_cobstacle(piece, shape) for piece in occ.zone)
            obstacles.extend(minkowski_cobstacle(occ.shape, piece) for piece in zone)
        if not obstacles or domain.is_empty:
            return domain
        return domain.difference(shapely.union_all(obstacles))

    def coverage(self) -> float:
        """Share of the surface covered by occupants' footprints."""
        if not self.occupants:
            return 0.0
        covered = shapely.union_all([o.shape for o in self.occupants.values()])
        return float(covered.intersection(self.surface).area / self.surface.area)

    def free_area(self) -> float:
        """Usable area covered by neither occupants nor keep-outs (square metres)."""
        shapes = [o.shape for o in self.occupants.values()] + [r for _, r in self.fixed]
        if not shapes:
            return float(self.usable.area)
        covered = shapely.union_all(shapes).intersection(self.usable)
        return float(max(0.0, self.usable.area - covered.area))


__all__ = ["Clearance", "Occupant", "SurfaceMap"]
