"""Context-aware placement: sample every object from the free space of a prohibited-region map.

Each support surface has a :class:`SurfaceMap`. The table's map starts with the robot base's
keep-out and the reserved zones; every placed footprint is added to it. An object's origin is
drawn uniformly from its domain (the table eroded by its footprint, within the arm's top-down
reach, its region and its relations) minus the configuration-space obstacles of everything on the
map, at a sampled yaw. Distractors keep extra clearance from task objects (more when tall), and
nothing stands where the open fingers go down to grasp a task object (its finger zone). When
an object does not fit, the most recently placed distractors are taken off again and re-placed
after it, a bounded number of times; then a :class:`PlacementError` names the object, the surface
and the free area left.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np
import shapely
from shapely import affinity
from shapely.geometry import Point, Polygon
from shapely.geometry.base import BaseGeometry

from vcage.assets.catalog import CATALOG
from vcage.errors import PlacementError
from vcage.scene.layout import LayoutObject, LayoutSpec
from vcage.scene.placement.base import PLACERS, PlacementStats, Placer, Pose, height, support_frame
from vcage.scene.placement.free_space import Occupant, SurfaceMap
from vcage.scene.placement.geometry import (
    drawer_zone,
    erode_box,
    footprint,
    grasp_zone,
    rotated_rect,
    sample_point,
    to_world,
)
from vcage.scene.spec import ROBOT_MOUNT

FAR = 10.0  # half-planes are boxes this large
FULL_TURN = (-math.pi, math.pi)
MIN_HALF = 1e-4  # a support surface is never thinner than this (m), so its polygon has an area
# Objects put on another one keep their origin over the middle half of its surface, so that a
# stack of several stays statically stable.
ON_INSET = 0.5


@PLACERS.register("context")
class ContextAwarePlacer(Placer):
    name = "context"

    def begin(self, layout: LayoutSpec) -> None:
        cfg = self.config
        (x0, x1), (y0, y1) = layout.table.x_range, layout.table.y_range
        self.layout = layout
        self.objects: dict[str, LayoutObject] = {o.name: o for o in layout.objects}
        self.table_box = (x0 + cfg.edge_margin, y0 + cfg.edge_margin,
                          x1 - cfg.edge_margin, y1 - cfg.edge_margin)
        self.reach_region = None if self.reach is None else self.reach.region(layout.table.height)
        top = shapely.box(x0, y0, x1, y1)
        usable = top if self.reach_region is None else top.intersection(self.reach_region)
        table = SurfaceMap("table", top, usable)
        table.forbid("robot base", Point(ROBOT_MOUNT[:2]).buffer(cfg.base_keepout, 16))
        for zone in layout.reserved:
            table.forbid(f"reserved zone {zone.name!r}", shapely.box(*zone.region.bounds))
        self.maps: dict[str, SurfaceMap] = {"table": table}
        self.backtracks = 0

    # -- placing with backtracking ---------------------------------------------------------------
    def place_all(self, objects: list[LayoutObject], rng: np.random.Generator,
                  stats: PlacementStats) -> dict[str, Pose]:
        self.objects.update({o.name: o for o in objects})
        poses: dict[str, Pose] = {}
        elapsed: dict[str, float] = {}
        order: list[str] = []
        queue = list(objects)
        while queue:
            obj = queue.pop(0)
            t0 = time.perf_counter()
            pose = self._place_one(obj, poses, rng)
            if pose is not None:
                self._commit(obj, pose)
                poses[obj.name] = pose
                order.append(obj.name)
            else:
                victim = next((n for n in reversed(order) if not self.objects[n].task), None)
                if victim is None or stats.backtracks >= self.config.max_backtracks:
                    raise self.failure(obj, poses)
                stats.backtracks = self.backtracks = stats.backtracks + 1
                self._uncommit(self.objects[victim])
                del poses[victim]
                order.remove(victim)
                queue[:0] = [obj, self.objects[victim]]
            elapsed[obj.name] = elapsed.get(obj.name, 0.0) + time.perf_counter() - t0
        stats.seconds.extend(elapsed[n] for n in order)
        return poses

    def _place_one(self, obj: LayoutObject, poses: dict[str, Pose],
                   rng: np.random.Generator) -> Pose | None:
        surface = self._surface(obj, poses)
        tall = height(obj) > self.config.tall_height
        pinned = obj.region is not None and max(obj.region.half) == 0 and obj.support.is_table
        for yaw in self._yaws(obj, poses, rng):
            shape = footprint(obj.type, obj.scale, yaw)
            domain = self._domain(obj, shape, poses)
            grown = shape.buffer(self.config.margin, join_style="mitre")
            zone = self._zone(obj, yaw, (0.0, 0.0))
            free = surface.free(grown, obj.task, tall, self._clearance, domain, zone)
            if pinned:
                assert obj.region is not None
                if free.distance(Point(obj.region.center)) <= 1e-9:
                    return Pose(obj.region.center, yaw)
                continue
            xy = sample_point(free, rng)
            if xy is not None:
                return Pose(xy, yaw)
        return None

    # -- the map ------------------------------------------------------------------------------------
    def _surface(self, obj: LayoutObject, poses: dict[str, Pose]) -> SurfaceMap:
        label = obj.support.label()
        if label not in self.maps:
            center, yaw, half = support_frame(obj, poses, self.objects)
            surface = SurfaceMap(label, rotated_rect(center, yaw, np.maximum(half, MIN_HALF)))
            room = self._room_on(obj, poses)
            if room is not None:
                surface.forbid(f"the room kept for what {obj.support.obj!r} receives", room)
            self.maps[label] = surface
        return self.maps[label]

    def _room_on(self, obj: LayoutObject, poses: dict[str, Pose]) -> Polygon | None:
        """The room a host keeps free on the surface ``obj`` stands on for what the robot will put
        there (as on the table, :meth:`_zone`): what already rests in a basket stays clear of where
        the hand sets the next object down. None if the host receives nothing there."""
        assert obj.support.obj is not None
        host = self.objects[obj.support.obj]
        otype = CATALOG.get(host.type)
        if not (self.config.finger_zones and host.receives > 0
                and otype.placement(host.receives_at).name == otype.placement(obj.support.placement).name):
            return None
        place, pose = otype.placement(host.receives_at), poses[host.name]
        center = to_world(pose.xy, pose.yaw, (place.pos[0] * host.scale, place.pos[1] * host.scale))
        return Point(center).buffer(host.receives + self.config.finger_slack, 16)

    def _domain(self, obj: LayoutObject, shape: Polygon, poses: dict[str, Pose]) -> BaseGeometry:
        """Where ``obj``'s origin may go before anything else on the surface is considered."""
        if not obj.support.is_table:
            return self._support_domain(obj, shape, poses)
        domain: BaseGeometry = erode_box(self.table_box, shape)
        if self.reach_region is not None and (obj.task or self.config.reach_distractors):
            domain = domain.intersection(self.reach_region)
        if obj.region is not None:
            x0, y0, x1, y1 = obj.region.bounds
            domain = domain.intersection(shapely.box(x0 - 1e-9, y0 - 1e-9, x1 + 1e-9, y1 + 1e-9))
        for rel in self.layout.relations:
            if rel.a == obj.name:
                domain = domain.intersection(_relation_region(rel.kind, poses[rel.b].xy, rel.distance)) \
                    if rel.kind != "far_from" else \
                    domain.difference(Point(poses[rel.b].xy).buffer(rel.distance, 32))
        return domain

    def _support_domain(self, obj: LayoutObject, shape: Polygon, poses: dict[str, Pose]) -> BaseGeometry:
        """On a surface the origin stays in the placement region (overhang allowed); in a
        container the whole footprint stays in it, so the object clears the walls."""
        center, syaw, half = support_frame(obj, poses, self.objects)
        if self._support_kind(obj) == "on":  # the origin stays over the middle of the surface
            return rotated_rect(center, syaw, np.maximum(half * ON_INSET, MIN_HALF))
        local_shape = affinity.rotate(shape, -syaw, origin=(0, 0), use_radians=True)
        local = erode_box((-half[0], -half[1], half[0], half[1]), local_shape)
        if local.is_empty:
            return local
        return affinity.translate(affinity.rotate(local, syaw, origin=(0, 0), use_radians=True),
                                  center[0], center[1])

    def _support_kind(self, obj: LayoutObject) -> str:
        assert obj.support.obj is not None
        host = self.objects[obj.support.obj]
        return CATALOG.get(host.type).placement(obj.support.placement).kind

    def _yaws(self, obj: LayoutObject, poses: dict[str, Pose], rng: np.random.Generator) -> list[float]:
        """The yaws to try, in order."""
        if obj.yaw[0] == obj.yaw[1]:
            return [obj.yaw[0]]
        if not obj.support.is_table and obj.yaw == FULL_TURN and self._support_kind(obj) == "in":
            # in a container, line up with its walls: each quarter turn once, slightly jittered
            assert obj.support.obj is not None
            host_yaw = poses[obj.support.obj].yaw
            return [host_yaw + int(k) * math.pi / 2 + float(rng.uniform(-0.1, 0.1))
                    for k in rng.permutation(4)]
        return [float(rng.uniform(*obj.yaw)) for _ in range(self.config.yaw_tries)]

    def _clearance(self, occ: Occupant, task: bool, tall: bool) -> float:
        if occ.task == task:
            return 0.0
        distractor_tall = tall if occ.task else occ.tall
        return self.config.tall_clearance if distractor_tall else self.config.task_clearance

    def _zone(self, obj: LayoutObject, yaw: float, xy: tuple[float, float]) -> tuple[Polygon, ...]:
        """The ground the hand needs around a task object on the table: its finger zones if the
        robot grasps it, the room of what it carries there if it receives something, where its
        drawer comes out if the robot opens it, and the room at its hook's end if something is hung
        on it."""
        if not (self.config.finger_zones and obj.task and obj.support.is_table):
            return ()
        slack = self.config.finger_slack
        pieces = grasp_zone(obj.type, obj.scale, yaw, xy, slack) if obj.grasped else ()
        if obj.receives > 0:
            place = CATALOG.get(obj.type).placement(obj.receives_at)
            center = to_world(xy, yaw, (place.pos[0] * obj.scale, place.pos[1] * obj.scale))
            pieces += (Point(center).buffer(obj.receives + slack, 16),)
        if obj.slides > 0:
            pieces += (drawer_zone(obj.type, obj.scale, yaw, obj.slides, xy, slack),)
        hook = CATALOG.get(obj.type).point_of_kind("hook")
        if obj.hangs > 0 and hook is not None:
            end = to_world(xy, yaw, (hook.pos[0] * obj.scale, hook.pos[1] * obj.scale))
            pieces += (Point(end).buffer(obj.hangs + slack, 16),)
        return pieces

    def _commit(self, obj: LayoutObject, pose: Pose) -> None:
        occ = Occupant(obj.name, footprint(obj.type, obj.scale, pose.yaw, pose.xy), obj.task,
                       height(obj) > self.config.tall_height, self._zone(obj, pose.yaw, pose.xy))
        self.maps["table"].add(occ)
        if not obj.support.is_table:
            self.maps[obj.support.label()].add(replace(occ, zone=()))

    def _uncommit(self, obj: LayoutObject) -> None:
        self.maps["table"].remove(obj.name)
        if not obj.support.is_table:
            self.maps[obj.support.label()].remove(obj.name)

    # -- reporting ----------------------------------------------------------------------------------
    def failure(self, obj: LayoutObject, poses: dict[str, Pose]) -> PlacementError:
        surface = self.maps.get(obj.support.label(), self.maps["table"])
        free = surface.free_area()
        size = footprint(obj.type, obj.scale, 0.0).bounds
        where = "within the arm's reach" if surface.label == "table" else "in the placement region"
        return PlacementError(
            f"no free space for {obj.name!r} ({obj.type}, footprint {size[2] - size[0]:.3f} x "
            f"{size[3] - size[1]:.3f} m) on {surface.label}: {free:.3f} m² of the "
            f"{surface.usable.area:.3f} m² {where} is free but no gap fits it (with "
            f"{len(poses)} objects placed, after {self.backtracks} backtracks); use fewer or "
            "smaller objects, a larger table, or a wider region")


def _relation_region(kind: str, b: tuple[float, float], distance: float) -> BaseGeometry:
    if kind == "left_of":  # +y is left as seen from the robot
        return shapely.box(-FAR, b[1] + distance, FAR, FAR)
    if kind == "right_of":
        return shapely.box(-FAR, -FAR, FAR, b[1] - distance)
    return Point(b).buffer(distance, 32)  # near
