"""Baselines behind the same interface as the context-aware method.

``naive`` (the paper's Vanilla): every origin is drawn uniformly from the table (kept on it) or
from its region or support, yaw uniformly; nothing is checked. ``rejection`` (as robosuite's
``UniformRandomSampler``): each object is a bounding cylinder; a pose is drawn uniformly and
kept when its circle clears every circle already on the same support (and its relations hold);
after a fixed number of tries the scene fails.
"""

from __future__ import annotations

import numpy as np

from vcage.assets.catalog import CATALOG
from vcage.errors import PlacementError
from vcage.scene.layout import LayoutObject, LayoutSpec, Relation
from vcage.scene.placement.base import PLACERS, Placer, Pose, support_frame
from vcage.scene.placement.geometry import to_world


class _UniformPlacer(Placer):
    """Draws an origin uniformly from the object's region, support region, or the table."""

    def begin(self, layout: LayoutSpec) -> None:
        self.layout = layout
        self.objects: dict[str, LayoutObject] = {o.name: o for o in layout.objects}

    def place_all(self, objects, rng, stats):  # type: ignore[no-untyped-def,override]
        self.objects.update({o.name: o for o in objects})
        return super().place_all(objects, rng, stats)

    def draw(self, obj: LayoutObject, poses: dict[str, Pose], rng: np.random.Generator,
             radius: float) -> Pose:
        yaw = float(rng.uniform(*obj.yaw)) if obj.yaw[0] < obj.yaw[1] else obj.yaw[0]
        if not obj.support.is_table:
            center, syaw, half = support_frame(obj, poses, self.objects)
            x, y = to_world(center, syaw, rng.uniform(-1, 1, 2) * half)
            return Pose((float(x), float(y)), yaw)
        (x0, x1), (y0, y1) = self.layout.table.x_range, self.layout.table.y_range
        if obj.region is not None:
            rx0, ry0, rx1, ry1 = obj.region.bounds
        else:  # keep the object's circle on the table
            rx0, ry0, rx1, ry1 = x0 + radius, y0 + radius, x1 - radius, y1 - radius
        return Pose((float(rng.uniform(rx0, rx1)), float(rng.uniform(ry0, ry1))), yaw)


@PLACERS.register("naive")
class NaivePlacer(_UniformPlacer):
    name = "naive"

    def _place_one(self, obj: LayoutObject, poses: dict[str, Pose],
                   rng: np.random.Generator) -> Pose | None:
        return self.draw(obj, poses, rng, _radius(obj))


@PLACERS.register("rejection")
class RejectionPlacer(_UniformPlacer):
    name = "rejection"

    def _place_one(self, obj: LayoutObject, poses: dict[str, Pose],
                   rng: np.random.Generator) -> Pose | None:
        r = _radius(obj)
        neighbours = [(np.asarray(p.xy), _radius(self.objects[n])) for n, p in poses.items()
                      if self.objects[n].support == obj.support]
        relations = [rel for rel in self.layout.relations if rel.a == obj.name]
        for _ in range(self.config.rejection_tries):
            pose = self.draw(obj, poses, rng, r)
            xy = np.asarray(pose.xy)
            if all(np.linalg.norm(xy - c) > r + rc for c, rc in neighbours) and \
                    all(_holds(rel, xy, poses) for rel in relations):
                return pose
        return None

    def failure(self, obj: LayoutObject, poses: dict[str, Pose]) -> PlacementError:
        return PlacementError(f"rejection placement found no pose for {obj.name!r} ({obj.type}) on "
                              f"{obj.support.label()} in {self.config.rejection_tries} tries "
                              f"(with {len(poses)} objects placed)")


def _radius(obj: LayoutObject) -> float:
    return CATALOG.get(obj.type).footprint_radius * obj.scale


def _holds(rel: Relation, xy: np.ndarray, poses: dict[str, Pose]) -> bool:
    b = np.asarray(poses[rel.b].xy)
    if rel.kind == "left_of":
        return bool(xy[1] >= b[1] + rel.distance)
    if rel.kind == "right_of":
        return bool(xy[1] <= b[1] - rel.distance)
    dist = float(np.linalg.norm(xy - b))
    return dist <= rel.distance if rel.kind == "near" else dist >= rel.distance
