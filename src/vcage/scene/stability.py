"""Physical validity of an instantiated scene: no interpenetration at t=0, nothing moves or falls.

:func:`check_stability` inspects the contacts of the freshly composed world (any pair of distinct
bodies deeper than ``penetration`` counts), lets it settle, and compares every object's pose with
where it started. A scene that fails carries the reason, naming the objects involved.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vcage.errors import SimulationError
from vcage.sim.world import World


@dataclass(frozen=True)
class StabilityConfig:
    settle_seconds: float = 1.0
    penetration: float = 0.001  # contacts deeper than this at t=0 count as interpenetration (m)
    max_shift: float = 0.01  # an object that moves further while settling is unstable (m)
    max_rotation: float = 0.1  # ... or turns further (rad)
    fall_depth: float = 0.05  # below the table top by this much: it fell off (m)


@dataclass(frozen=True)
class StabilityReport:
    penetrations: tuple[tuple[str, str, float], ...] = ()  # (body a, body b, depth m)
    moved: tuple[tuple[str, float, float], ...] = ()  # (object, shift m, rotation rad)
    fell: tuple[str, ...] = ()
    error: str | None = None  # the physics blew up while settling

    @property
    def interpenetrating(self) -> bool:
        return bool(self.penetrations)

    @property
    def stable(self) -> bool:
        return not (self.moved or self.fell or self.error)

    @property
    def ok(self) -> bool:
        return self.stable and not self.interpenetrating

    def reason(self) -> str:
        parts = []
        if self.penetrations:
            a, b, d = max(self.penetrations, key=lambda p: p[2])
            parts.append(f"{len(self.penetrations)} interpenetrating contacts (deepest {a}/{b} "
                         f"{d * 1000:.1f} mm)")
        if self.moved:
            name, shift, rot = max(self.moved, key=lambda m: m[1])
            parts.append(f"{len(self.moved)} objects moved while settling ({name}: "
                         f"{shift * 1000:.0f} mm, {math.degrees(rot):.0f} deg)")
        if self.fell:
            parts.append(f"fell off the table: {', '.join(self.fell)}")
        if self.error:
            parts.append(f"unstable physics: {self.error}")
        return "; ".join(parts) or "stable"


def penetrations(world: World, depth: float) -> list[tuple[str, str, float]]:
    """Contacts between distinct bodies (of distinct objects) deeper than ``depth``."""
    d, m = world.data, world.model
    found = []
    for i in range(d.ncon):
        con = d.contact[i]
        if con.dist >= -depth:
            continue
        a, b = world.body_owner(m.geom_bodyid[con.geom1]), world.body_owner(m.geom_bodyid[con.geom2])
        if a != b:
            found.append((a, b, float(-con.dist)))
    return found


def fused(world: World, names: set[str] | frozenset[str], depth: float) -> tuple[tuple[str, str, float], ...]:
    """The pairs of objects, one of them in ``names``, whose deepest contact (as the world's contacts
    stand) is deeper than ``depth``, deepest first: objects fused into each other, as naive placement
    leaves them even after settling (objects resting on one another sink well under a millimetre)."""
    objects, deepest = set(world.object_names), dict[tuple[str, str], float]()
    for a, b, d in penetrations(world, depth):
        if a in objects and b in objects and (a in names or b in names):
            key = (min(a, b), max(a, b))
            deepest[key] = max(d, deepest.get(key, 0.0))
    return tuple(sorted(((a, b, d) for (a, b), d in deepest.items()), key=lambda p: -p[2]))


def check_stability(world: World, config: StabilityConfig | None = None) -> StabilityReport:
    """Check the world as composed (call before stepping it), then settle it and check again."""
    cfg = config or StabilityConfig()
    try:
        world.forward()
    except SimulationError as exc:
        return StabilityReport(error=str(exc))
    pens = tuple(penetrations(world, cfg.penetration))
    start = {n: (world.object_pos(n), world.object_mat(n)) for n in world.objects}
    try:
        world.settle(cfg.settle_seconds)
    except SimulationError as exc:
        return StabilityReport(pens, error=str(exc))
    top = world.table_top()
    moved, fell = [], []
    for name, (pos, mat) in start.items():
        now, rot = world.object_pos(name), world.object_mat(name)
        if now[2] < top - cfg.fall_depth:
            fell.append(name)
            continue
        shift = float(np.linalg.norm(now - pos))
        cos = (np.trace(mat.T @ rot) - 1) / 2
        angle = float(np.arccos(np.clip(cos, -1.0, 1.0)))
        if shift > cfg.max_shift or angle > cfg.max_rotation:
            moved.append((name, shift, angle))
    return StabilityReport(pens, tuple(moved), tuple(fell))
