"""Planar geometry for placement: footprints, configuration-space obstacles, uniform sampling.

Positions are the (x, y) of an object's origin. For a new object with footprint ``F`` (a convex
polygon about its origin at a given yaw), the origins where it would overlap an obstacle ``O`` form
the Minkowski sum ``O ⊕ (−F)``; for convex polygons that is the convex hull of all vertex sums.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import shapely
from shapely.geometry import MultiPoint, Point, Polygon
from shapely.geometry.base import BaseGeometry

from vcage.assets.catalog import CATALOG
from vcage.sim.robot import FINGER_HALF_WIDTH, FINGER_OUTER, FINGER_THICKNESS

EMPTY = Polygon()
Vec2 = Sequence[float] | np.ndarray  # an (x, y) pair


def footprint(type_name: str, scale: float, yaw: float, xy: tuple[float, float] = (0.0, 0.0),
              pad: float = 0.0) -> Polygon:
    """The object's resting rectangle (its size box, grown by ``pad``) at ``xy`` and ``yaw``."""
    sx, sy = (s * scale for s in CATALOG.get(type_name).size[:2])
    return rotated_rect(xy, yaw, (sx / 2 + pad, sy / 2 + pad))


def grasp_zone(type_name: str, scale: float, yaw: float, xy: tuple[float, float] = (0.0, 0.0),
               slack: float = 0.0) -> tuple[Polygon, ...]:
    """Where the open fingers go down when ``type_name`` at ``xy`` and ``yaw`` is grasped: for
    every annotated grasp (identical ones once), the box of the open fingers grown by ``slack``.
    Another object's footprint in any of them blocks that grasp. Empty without grasps."""
    half = (FINGER_HALF_WIDTH + slack, FINGER_OUTER + slack)  # gripper x, closing axis
    boxes: list[Polygon] = []
    for g in CATALOG.get(type_name).grasps:
        center = to_world(xy, yaw, (g.pos[0] * scale, g.pos[1] * scale))
        box = rotated_rect(center, yaw + g.yaw, half)
        if not any(box.symmetric_difference(b).area < 1e-10 for b in boxes):  # e.g. yaw and yaw + pi
            boxes.append(box)
    return tuple(boxes)


def drawer_zone(type_name: str, scale: float, yaw: float, out: float, xy: tuple[float, float] = (0.0, 0.0),
                slack: float = 0.0) -> Polygon:
    """The ground a drawer of ``type_name`` sweeps when it comes ``out`` metres out along its
    handle's direction, as wide as the object, and the hand's reach beyond the handle there (the
    fingers close along the slide), grown by ``slack``. Empty without a drawer handle."""
    otype = CATALOG.get(type_name)
    handle = otype.drawer_handle()
    if handle is None or out <= 0:
        return EMPTY
    sx, sy = (s * scale / 2 for s in otype.size[:2])
    direction = math.atan2(handle.direction[1], handle.direction[0])  # in the object's frame
    depth = out + FINGER_OUTER + slack  # beyond the footprint's edge on the handle's side
    edge = abs(sx * math.cos(direction)) + abs(sy * math.sin(direction))
    across = abs(sx * math.sin(direction)) + abs(sy * math.cos(direction))
    center = to_world(xy, yaw + direction, (edge + depth / 2, 0.0))
    return rotated_rect(center, yaw + direction, (depth / 2, across + slack))


def carry_radius(type_name: str, scale: float) -> float:
    """How far from its origin ``type_name`` held in the hand reaches, closed fingers included, for
    the widest of its grasps: the room it needs where it is put down."""
    otype = CATALOG.get(type_name)
    sx, sy = (s * scale / 2 for s in otype.size[:2])
    corners = [np.hypot(sx, sy)]
    for g in otype.grasps:
        box = rotated_rect((g.pos[0] * scale, g.pos[1] * scale), g.yaw,
                           (FINGER_HALF_WIDTH, g.width * scale / 2 + FINGER_THICKNESS))
        corners.extend(float(np.hypot(x, y)) for x, y in list(box.exterior.coords)[:-1])
    return float(max(corners))


def to_world(center: Vec2, yaw: float, local: Vec2) -> np.ndarray:
    """The world (x, y) of ``local``, given in a frame at ``center`` turned by ``yaw``."""
    c, s = math.cos(yaw), math.sin(yaw)
    return np.asarray(center[:2], dtype=float) + [c * local[0] - s * local[1], s * local[0] + c * local[1]]


def rotated_rect(center: Vec2, yaw: float, half: Vec2) -> Polygon:
    """The rectangle with half extents ``half`` centred at ``center`` and turned by ``yaw``."""
    hx, hy = float(half[0]), float(half[1])
    return Polygon([tuple(to_world(center, yaw, corner))
                    for corner in ((hx, hy), (-hx, hy), (-hx, -hy), (hx, -hy))])


def minkowski_cobstacle(obstacle: Polygon, shape: Polygon) -> Polygon:
    """Origins at which ``shape`` (a convex polygon about the origin) touches convex ``obstacle``."""
    a = np.asarray(obstacle.exterior.coords)[:-1]
    b = -np.asarray(shape.exterior.coords)[:-1]
    sums = (a[:, None, :] + b[None, :, :]).reshape(-1, 2)
    hull = MultiPoint(sums).convex_hull
    return hull if isinstance(hull, Polygon) else EMPTY


def erode_box(bounds: tuple[float, float, float, float], shape: Polygon) -> Polygon:
    """Origins at which ``shape`` lies inside the axis-aligned box ``bounds`` (exact for a box)."""
    sx0, sy0, sx1, sy1 = shape.bounds
    x0, y0, x1, y1 = bounds
    x0, y0, x1, y1 = x0 - sx0, y0 - sy0, x1 - sx1, y1 - sy1
    if x1 < x0 or y1 < y0:
        return EMPTY
    return shapely.box(x0, y0, x1, y1)


def annulus(center: tuple[float, float], r_in: float, r_out: float, resolution: int = 32) -> BaseGeometry:
    """The points between radii ``r_in`` and ``r_out``, approximated conservatively: the outer
    circle by an inscribed polygon, the hole by a circumscribed one."""
    ring = Point(center).buffer(r_out, resolution)
    if r_in <= 0:
        return ring
    grow = 1.0 / math.cos(math.pi / (4 * resolution))  # buffer() uses 4 * resolution segments
    return ring.difference(Point(center).buffer(r_in * grow, resolution))


def sample_point(region: BaseGeometry, rng: np.random.Generator) -> tuple[float, float] | None:
    """A point drawn uniformly from the area of ``region`` (None if it has no area).

    The region is triangulated (constrained Delaunay, holes respected); a triangle is drawn in
    proportion to its area and a point uniformly inside it.
    """
    if region.is_empty or region.area <= 1e-12:
        return None
    polys = [g for g in getattr(region, "geoms", [region]) if isinstance(g, Polygon) and g.area > 0]
    tris = []
    for poly in polys:
        tris.extend(shapely.constrained_delaunay_triangles(poly).geoms)
    areas = np.array([t.area for t in tris])
    if areas.sum() <= 0:
        return None
    tri = tris[int(rng.choice(len(tris), p=areas / areas.sum()))]
    a, b, c = np.asarray(tri.exterior.coords)[:3]
    u, v = rng.random(2)
    if u + v > 1:
        u, v = 1 - u, 1 - v
    p = a + u * (b - a) + v * (c - a)
    return float(p[0]), float(p[1])


def point_region(xy: tuple[float, float], tol: float = 1e-4) -> Polygon:
    """A tiny square around ``xy``: a pinned position that must still be free."""
    return shapely.box(xy[0] - tol, xy[1] - tol, xy[0] + tol, xy[1] + tol)
