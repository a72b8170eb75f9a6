"""The refine agent: ``P* = argmin L_collision(P) + lambda * L_semantic(P, D_scene)``.

Gradient descent (Adam, forward-difference gradients evaluated as one batch) from a bounded number
of starts: the matched poses, the same with ordered objects put in order and every supported object
moved onto its host, then seeded jitters of both. The first start whose result has no penetration
(half the margin kept free), no
footprint off the table or out of reach, and every relation within ``tolerance`` is accepted; after
the last start a :class:`RefineRejected` names the worst violations of the best result. Every
descent runs all its iterations: Adam's steps do not shrink as the cost levels off, so stopping at
the first acceptable arrangement leaves objects at the edge of their margins (measured: the mean
displacement of the final refine from the matched poses doubled).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from vcage.synthesis.costs import Problem, Weights, max_violation, objective
from vcage.synthesis.errors import RefineRejected
from vcage.synthesis.footprints import to_local, wrap

Poses = dict[str, tuple[float, float, float]]


@dataclass(frozen=True)
class RefineConfig:
    weights: Weights = field(default_factory=Weights)
    starts: int = 4
    iterations: int = 400
    step: float = 0.004  # metres per Adam step at the start (yaw: x5 rad)
    jitter: float = 0.04  # metres of the seeded restarts' jitter
    tolerance: float = 0.002  # metres of violation accepted
    epsilon: float = 1e-4  # forward-difference step


@dataclass(frozen=True)
class RefineResult:
    poses: Poses
    start: int  # which start was accepted
    starts_tried: int
    violations: dict[str, float]
    cost: float
    seconds: float
    displacement: float  # mean distance of the refined origins from the matched ones (m)

    def to_dict(self) -> dict[str, object]:
        return {"poses": {n: [round(v, 5) for v in p] for n, p in self.poses.items()}, "start": self.start,
                "starts_tried": self.starts_tried, "violations": self.violations, "cost": self.cost,
                "seconds": round(self.seconds, 4), "mean_displacement_m": round(self.displacement, 5)}


def _as_array(problem: Problem, poses: Poses) -> np.ndarray:
    return np.array([poses[n] for n in problem.names], dtype=float)


def snap_to_hosts(problem: Problem, ps: np.ndarray) -> np.ndarray:
    """``ps`` with every supported object at the centre of its host's placement region (hosts first)."""
    out = ps.copy()
    order = sorted(range(len(ps)), key=lambda i: _depth(problem, i))
    for i in order:
        h = int(problem.parent[i])
        if h < 0:
            continue
        c, s = np.cos(out[h, 2]), np.sin(out[h, 2])
        cx, cy = problem.region[i, :2]
        out[i, :2] = out[h, :2] + [c * cx - s * cy, s * cx + c * cy]
        if problem.inside[i]:
            # turn the child with its host, the long sides together
            out[i, 2] = out[h, 2] + (0.0 if (problem.half[i, 0] >= problem.half[i, 1]) ==
                                     (problem.region[i, 2] >= problem.region[i, 3]) else np.pi / 2)
    return out


def ordered(problem: Problem, ps: np.ndarray) -> np.ndarray:
    """``ps`` with the positions of ordered objects permuted so that every ``left_of`` / ``right_of``
    (along y) and ``in_front_of`` / ``behind`` (along x) already holds in sequence: crossing objects
    would otherwise block each other's way."""
    out = ps.copy()
    for axis, before, after, sign in ((1, "left_of", "right_of", -1.0), (0, "in_front_of", "behind", 1.0)):
        edges = [(a, b) if k == before else (b, a)
                 for k, a, b, _ in problem.relations if k in (before, after)]
        members = sorted({i for e in edges for i in e})
        if not members:
            continue
        order: list[int] = []
        pending = list(members)
        while pending:
            ready = [i for i in pending if not any(b == i and a in pending for a, b in edges)]
            nxt = ready[0] if ready else pending[0]
            order.append(nxt)
            pending.remove(nxt)
        values = sorted((out[i, axis] for i in members), key=lambda v: sign * v)
        for i, val in zip(order, values, strict=True):
            out[i, axis] = val
    return out


def _depth(problem: Problem, i: int) -> int:
    d = 0
    while problem.parent[i] >= 0 and d < len(problem.parent):
        i, d = int(problem.parent[i]), d + 1
    return d


def descend(problem: Problem, start: np.ndarray, anchor: np.ndarray, cfg: RefineConfig) -> np.ndarray:
    n = len(start)
    x = start.copy()
    eps = cfg.epsilon
    basis = np.zeros((3 * n, n, 3))
    basis[np.arange(3 * n), np.repeat(np.arange(n), 3), np.tile(np.arange(3), n)] = eps
    lr = np.tile([cfg.step, cfg.step, 5 * cfg.step], (n, 1))
    m, v = np.zeros_like(x), np.zeros_like(x)
    b1, b2 = 0.9, 0.999
    for k in range(1, cfg.iterations + 1):
        costs = objective(problem, np.concatenate([x[None], x[None] + basis]), anchor, cfg.weights)
        g = ((costs[1:] - costs[0]) / eps).reshape(n, 3)
        if not np.any(g):
            break
        m = b1 * m + (1 - b1) * g
        v = b2 * v + (1 - b2) * g * g
        decay = 1.0 if k < cfg.iterations // 2 else 0.3
        x = x - decay * lr * (m / (1 - b1**k)) / (np.sqrt(v / (1 - b2**k)) + 1e-12)
        x[:, 2] = wrap(x[:, 2])
    return x


def accepted(problem: Problem, ps: np.ndarray, tolerance: float) -> tuple[bool, dict[str, float]]:
    viol = max_violation(problem, ps)
    return all(val <= tolerance for val in viol.values()), viol


def refine(problem: Problem, matched: Poses, cfg: RefineConfig | None = None,
           rng: np.random.Generator | None = None) -> RefineResult:
    """Refined poses for ``matched`` (every object of the problem); raises :class:`RefineRejected`."""
    cfg = cfg or RefineConfig()
    rng = rng if rng is not None else np.random.default_rng(0)
    t0 = time.perf_counter()
    anchor = _as_array(problem, matched)
    candidates = [anchor, snap_to_hosts(problem, ordered(problem, anchor))]
    best: tuple[float, np.ndarray, dict[str, float]] | None = None
    for k in range(cfg.starts):
        start = candidates[k % 2].copy()
        if k >= 2:
            start[:, :2] += rng.normal(0, cfg.jitter, (len(start), 2))
            start[:, 2] += rng.normal(0, 0.3, len(start))
            start = snap_to_hosts(problem, start) if k % 2 else start
        ps = descend(problem, start, anchor, cfg)
        ok, viol = accepted(problem, ps, cfg.tolerance)
        cost = float(objective(problem, ps[None], anchor, cfg.weights)[0])
        if ok:
            return _result(problem, ps, anchor, k, k + 1, viol, cost, t0)
        if best is None or cost < best[0]:
            best = (cost, ps, viol)
    assert best is not None
    worst = ", ".join(f"{name} {val * 1000:.1f} mm" for name, val in best[2].items() if val > cfg.tolerance)
    raise RefineRejected(f"no collision-free arrangement satisfying the description after {cfg.starts} "
                         f"starts (best: {worst}): use fewer or smaller objects, or fewer relations")


def _result(problem: Problem, ps: np.ndarray, anchor: np.ndarray, start: int, tried: int,
            viol: dict[str, float], cost: float, t0: float) -> RefineResult:
    poses = {n: (float(p[0]), float(p[1]), float(p[2])) for n, p in zip(problem.names, ps, strict=True)}
    disp = float(np.hypot(*(ps[:, :2] - anchor[:, :2]).T).mean())
    return RefineResult(poses, start, tried, {k: round(v, 6) for k, v in viol.items()}, cost,
                        time.perf_counter() - t0, disp)


def local_offset(problem: Problem, ps: np.ndarray, i: int) -> np.ndarray:
    """Where object ``i`` sits in its host's frame (for reports)."""
    return to_local(ps[i, :2], ps[int(problem.parent[i])])
