"""The refine objective ``L_collision(ps) + lambda * L_semantic(ps, D_scene)`` over batches of pose sets.

``L_collision``: squared penetration of footprint pairs (plus a margin), of footprint corners beyond
the table's edge, and of origins outside the arm's reach. ``L_semantic``: squared deviation from
the poses matched in the goal image, and squared hinges of the description's relations (see
:mod:`vcage.synthesis.description` for what each relation means). Objects resting on another are
never tested against the objects below them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vcage.assets.catalog import CATALOG
from vcage.scene.spec import TableSpec
from vcage.synthesis.description import SceneDescription
from vcage.synthesis.footprints import corners, penetration, to_local, wrap

ALIGN_TOL = 0.01  # metres: ``aligned`` objects share x within this
ON_CENTRAL = 0.5  # an object ``on`` another keeps its origin in this central share of the surface


@dataclass(frozen=True)
class Weights:
    lam: float = 1.0  # lambda: semantic against collision
    collision: float = 1e3
    relation: float = 1e3  # inside L_semantic
    deviation: float = 1.0  # inside L_semantic (per m^2)
    yaw: float = 0.02  # inside L_semantic (per rad^2)


@dataclass(frozen=True)
class Problem:
    """Everything the objective needs, as arrays over the description's objects (in its order)."""

    names: tuple[str, ...]
    half: np.ndarray  # (n, 2)
    radius: np.ndarray  # (n,)
    parent: np.ndarray  # (n,) index of the object it rests on, -1 for the table
    region: np.ndarray  # (n, 4): host-frame centre (x, y) and half extents of the child's placement
    inside: np.ndarray  # (n,) the child must fit inside its region (else its origin must lie on it)
    pairs: np.ndarray  # (M, 2) pairs tested for collision
    relations: tuple[tuple[str, int, int, float], ...]
    table: tuple[float, float, float, float]  # x0, y0, x1, y1 usable by footprints
    reach: tuple[float, float, float, float] | None  # mount x, y, r_in, r_out
    margin: float

    @classmethod
    def build(cls, desc: SceneDescription, table: TableSpec = TableSpec(), margin: float = 0.008,
              edge: float = 0.02, reach: tuple[float, float, float, float] | None = None) -> Problem:
        names = tuple(o.name for o in desc.objects)
        idx = {n: i for i, n in enumerate(names)}
        half = np.array([o.half_extents() for o in desc.objects])
        parent = np.full(len(names), -1)
        region = np.zeros((len(names), 4))
        inside = np.zeros(len(names), dtype=bool)
        for r in desc.relations:
            if r.kind in ("on", "inside"):
                i, h = idx[r.a], idx[r.b]
                host = desc.objects[h]
                place = next(p for p in CATALOG.get(host.type).placements
                             if p.kind == ("on" if r.kind == "on" else "in"))
                parent[i] = h
                inside[i] = r.kind == "inside"
                region[i] = [place.pos[0] * host.scale, place.pos[1] * host.scale,
                             place.half_size[0] * host.scale, place.half_size[1] * host.scale]
        pairs = [(i, j) for i in range(len(names)) for j in range(i + 1, len(names))
                 if not _related(i, j, parent)]
        rels = tuple((r.kind, idx[r.a], idx[r.b], r.gap) for r in desc.relations
                     if r.kind not in ("on", "inside"))
        (x0, x1), (y0, y1) = table.x_range, table.y_range
        return cls(names, half, np.hypot(half[:, 0], half[:, 1]), parent, region, inside,
                   np.array(pairs, dtype=int).reshape(-1, 2), rels,
                   (x0 + edge, y0 + edge, x1 - edge, y1 - edge),
                   reach, margin)

    @property
    def on_table(self) -> np.ndarray:
        return self.parent < 0


def _related(i: int, j: int, parent: np.ndarray) -> bool:
    def chain(k: int) -> set[int]:
        out = set()
        while parent[k] >= 0 and k not in out:
            out.add(k)
            k = int(parent[k])
        return out | {k}
    return j in chain(i) or i in chain(j)


def collision_terms(p: Problem, ps: np.ndarray) -> dict[str, np.ndarray]:
    """Violations (metres, >= 0) of the physical constraints, per term: (..., K) arrays."""
    pen = penetration(ps, p.half, p.pairs) + p.margin
    cs = corners(ps, p.half)[..., p.on_table, :, :]
    x0, y0, x1, y1 = p.table
    edge = np.concatenate([x0 - cs[..., 0], cs[..., 0] - x1, y0 - cs[..., 1], cs[..., 1] - y1], -1)
    out = {"penetration": np.maximum(pen, 0.0), "bounds": np.maximum(edge.reshape(*ps.shape[:-2], -1), 0.0)}
    if p.reach is not None:
        mx, my, r_in, r_out = p.reach
        r = np.hypot(ps[..., p.on_table, 0] - mx, ps[..., p.on_table, 1] - my)
        out["reach"] = np.concatenate([np.maximum(r_in - r, 0), np.maximum(r - r_out, 0)], -1)
    return out


def relation_terms(p: Problem, ps: np.ndarray) -> np.ndarray:
    """Hinge violation (metres, >= 0) of every relation, supports first: (..., K)."""
    vals: list[np.ndarray] = []  # each (..., k)
    child = np.nonzero(p.parent >= 0)[0]
    if len(child):
        host = ps[..., p.parent[child], :]
        reg = p.region[child]
        # the child's origin in its host's frame, off the placement region: on a surface, its central
        # part; inside a container, where the child's whole footprint stays on the floor (the centre
        # if it is larger than the floor: it then rests on the walls, and the physics check judges)
        origin = to_local(ps[..., child, :2], host) - reg[:, :2]
        rel = ps[..., child, 2] - host[..., 2]
        c, s = np.abs(np.cos(rel)), np.abs(np.sin(rel))
        hx, hy = p.half[child, 0], p.half[child, 1]
        extent = np.stack([c * hx + s * hy, s * hx + c * hy], -1)
        room = np.where(p.inside[child][:, None], np.maximum(reg[:, 2:] - extent, 0.0),
                        ON_CENTRAL * reg[:, 2:])
        vals.append(np.maximum(np.abs(origin) - room, 0).max(-1))
    cs = corners(ps, p.half)
    for kind, a, b, gap in p.relations:
        ca, cb = cs[..., a, :, :], cs[..., b, :, :]
        if kind == "left_of":
            v = gap - (ca[..., 1].min(-1) - cb[..., 1].max(-1))
        elif kind == "right_of":
            v = gap - (cb[..., 1].min(-1) - ca[..., 1].max(-1))
        elif kind == "in_front_of":
            v = gap - (cb[..., 0].min(-1) - ca[..., 0].max(-1))
        elif kind == "behind":
            v = gap - (ca[..., 0].min(-1) - cb[..., 0].max(-1))
        elif kind == "near":
            d = np.hypot(ps[..., a, 0] - ps[..., b, 0], ps[..., a, 1] - ps[..., b, 1])
            v = d - (p.radius[a] + p.radius[b] + gap)
        else:  # aligned
            v = np.abs(ps[..., a, 0] - ps[..., b, 0]) - ALIGN_TOL
        vals.append(np.maximum(v, 0.0)[..., None])
    if not vals:
        return np.zeros((*ps.shape[:-2], 0))
    return np.concatenate(vals, -1)


def objective(p: Problem, ps: np.ndarray, anchor: np.ndarray, w: Weights) -> np.ndarray:
    """The refine cost of each pose set in the batch ``ps`` (..., n, 3); ``anchor``: the matched poses."""
    col = sum((v**2).sum(-1) for v in collision_terms(p, ps).values())
    rel = (relation_terms(p, ps) ** 2).sum(-1)
    dev = ((ps[..., :2] - anchor[..., :2]) ** 2).sum((-1, -2))
    yaw = (wrap(ps[..., 2] - anchor[..., 2]) ** 2).sum(-1)
    return w.collision * col + w.lam * (w.relation * rel + w.deviation * dev + w.yaw * yaw)


def max_violation(p: Problem, ps: np.ndarray) -> dict[str, float]:
    """The largest violation of each kind for one pose set (n, 3), metres."""
    out = {k: float(v.max(initial=0.0)) for k, v in collision_terms(p, ps).items()}
    out["penetration"] = float((penetration(ps, p.half, p.pairs) + p.margin / 2).max(initial=-math.inf))
    out["penetration"] = max(out["penetration"], 0.0)
    out["relations"] = float(relation_terms(p, ps).max(initial=0.0))
    return out
