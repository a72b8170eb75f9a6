"""Template matching and 2D -> 3D: find each object of ``I_init`` in ``I_goal`` (the only OpenCV import).

1. **Register** ``I_goal`` to ``I_init`` globally (a scale sweep, each scale's shift by phase
   correlation of edges, the scale whose aligned edges differ least from the empty table's on the
   pixels that show no object in ``I_init``), undo that transform, and match the colour statistics.
2. **Match** each object: its pixels (and a faint ring of the empty table around them) turned about
   its origin, matched by masked squared difference over yaw, coarse (half resolution, 10 degree
   steps) then fine (full resolution, 2 degree steps, sub-pixel peak).
3. **Assign**: objects that look alike (same type, colour and scale) share candidate peaks and get
   the assignment of least total cost; then no two objects may claim one place unless one rests on
   the other (an object whose place agrees with its template keeps it against one whose place does
   not, e.g. an object the image model dropped; between equals the larger template keeps it).
4. **Lose**: an object whose best place agrees with its template on under half its pixels is lost.
5. **Lift** the origin pixel to the table with the camera's exact geometry
   (:class:`~vcage.sim.camera.OrthoCamera`), and the image rotation to a yaw.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass, field

import cv2
import numpy as np

from vcage.synthesis.errors import MatchingError
from vcage.synthesis.views import TopView

COARSE_STEP = 10.0  # degrees
FINE_SPAN, FINE_STEP = 8.0, 2.0  # degrees around the coarse yaw
RING = 4  # pixels of empty table around a template
RING_WEIGHT = 0.3
TELLING = 30.0  # colour distance (0..441) from the empty table that makes a template pixel telling
INLIER_DIFF = 60.0  # ... and no further than this from the template's colour
INLIER_MARGIN = 10.0  # a telling pixel agrees when it is this much closer to the object than the table
MIN_INLIERS = 0.5  # share of a template's telling pixels that must agree for the object to be found
RATIO_FLOOR = 200.0  # mean squared colour distance added to the table's error in the score's ratio
SCALE_SPAN, SCALE_STEP = 0.05, 0.005  # global scales the registration tries
MIN_RESPONSE = 0.02  # phase-correlation peak below which the registration counts as failed
CLASH = 0.7  # two objects closer than this share of the larger template radius claim one place
CANDIDATES = 10  # peaks kept per object for the assignment


Candidate = tuple[float, float, float, float]  # score, u, v, angle (degrees)


@dataclass(frozen=True)
class Match:
    name: str
    found: bool
    xy: tuple[float, float]
    yaw: float
    pixel: tuple[float, float]  # origin in I_init's pixel frame
    error: float  # the template's squared colour error over the empty table's (lower is better)
    inliers: float

    def to_dict(self) -> dict[str, object]:
        return {"name": self.name, "found": self.found, "xy": [round(v, 5) for v in self.xy],
                "yaw": round(self.yaw, 4), "pixel": [round(v, 2) for v in self.pixel],
                "error": round(self.error, 2), "inliers": round(self.inliers, 3)}


@dataclass(frozen=True)
class MatchReport:
    matches: dict[str, Match]
    warp: list[list[float]]  # I_init pixel -> I_goal pixel (2x3)
    registered: bool
    seconds: float
    aligned_goal: np.ndarray = field(repr=False)

    @property
    def lost(self) -> list[str]:
        return [n for n, m in self.matches.items() if not m.found]

    def to_dict(self) -> dict[str, object]:
        return {"registered": self.registered, "warp": self.warp, "seconds": round(self.seconds, 3),
                "lost": self.lost, "matches": [m.to_dict() for m in self.matches.values()]}


def _edges(image: np.ndarray) -> np.ndarray:
    gray = cv2.GaussianBlur(cv2.cvtColor(image, cv2.COLOR_RGB2GRAY).astype(np.float32), (5, 5), 1.5)
    return cv2.magnitude(cv2.Sobel(gray, cv2.CV_32F, 1, 0), cv2.Sobel(gray, cv2.CV_32F, 0, 1))


def register(empty: np.ndarray, goal: np.ndarray, mask: np.ndarray) -> tuple[np.ndarray, bool]:
    """The similarity (2x3: I_init pixel -> I_goal pixel) that best aligns the goal's edges with the
    empty table's: a scale sweep, each scale's shift by phase correlation; kept is the scale whose
    aligned edges, each map divided by its mean, differ least from the empty table's (edges: a colour
    cast or JPEG noise is no misalignment). ``mask`` marks the pixels that show no object in I_init
    (only they are compared)."""
    h, w = empty.shape[:2]
    centre = ((w - 1) / 2, (h - 1) / 2)
    ref = _edges(empty) * mask.astype(np.float32)
    edges = _edges(goal)
    window = cv2.createHanningWindow((w, h), cv2.CV_32F)
    plain = ref[mask] / (ref[mask].mean() + 1e-6)
    best: tuple[float, np.ndarray, float] | None = None
    for scale in np.arange(1 - SCALE_SPAN, 1 + SCALE_SPAN + 1e-9, SCALE_STEP):
        m = cv2.getRotationMatrix2D(centre, 0.0, float(scale))  # init pixel -> goal pixel at this scale
        back = cv2.warpAffine(edges, m, (w, h), flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP)
        (dx, dy), response = cv2.phaseCorrelate(ref, back * mask.astype(np.float32), window)
        warp = m.copy()
        warp[:, 2] += np.array([dx * scale, dy * scale])
        moved = _unwarp(edges, warp)[mask]
        error = float(np.abs(moved / (moved.mean() + 1e-6) - plain).mean())  # edges: no colour cast
        if best is None or error < best[0]:
            best = (error, warp, float(response))
    assert best is not None
    return best[1], best[2] > MIN_RESPONSE


def _unwarp(goal: np.ndarray, warp: np.ndarray) -> np.ndarray:
    return cv2.warpAffine(goal, warp, (goal.shape[1], goal.shape[0]),
                          flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP, borderMode=cv2.BORDER_REPLICATE)


def normalise_colour(goal: np.ndarray, init: np.ndarray, mask: np.ndarray) -> np.ndarray:
    g, i = goal[mask].astype(np.float32), init[mask].astype(np.float32)
    gain = (i.std(0) + 1e-3) / (g.std(0) + 1e-3)
    out = (goal.astype(np.float32) - g.mean(0)) * gain + i.mean(0)
    return np.clip(out, 0, 255)


@dataclass
class _Template:
    name: str
    center: np.ndarray  # origin pixel in I_init
    radius: int
    rgb: np.ndarray
    weight: np.ndarray
    look: tuple[object, ...]

    def turned(self, angle: float, scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        size = 2 * self.radius + 1
        m = cv2.getRotationMatrix2D((float(self.center[0]), float(self.center[1])), angle, 1.0)
        m[:, 2] += self.radius - self.center
        rgb = cv2.warpAffine(self.rgb, m, (size, size), flags=cv2.INTER_LINEAR)
        w = cv2.warpAffine(self.weight, m, (size, size), flags=cv2.INTER_LINEAR)
        if scale != 1.0:
            rgb = cv2.resize(rgb, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA)
            w = cv2.resize(w, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA)
        return rgb, w


def _templates(view: TopView, empty: np.ndarray,
               looks: Mapping[str, tuple[object, ...]]) -> list[_Template]:
    out = []
    kernel = np.ones((2 * RING + 1, 2 * RING + 1), np.uint8)
    for name in view.names:
        mask = view.mask(name)
        if mask.sum() < 12:
            continue  # hidden (under the robot): nothing to match
        x, y, _ = view.poses[name]
        c = view.camera.to_pixel(np.array([[x, y]]), view.heights[name])[0]
        vs, us = np.nonzero(mask)
        radius = int(math.ceil(np.hypot(us - c[0], vs - c[1]).max())) + RING + 2
        ring = (cv2.dilate(mask.astype(np.uint8), kernel) > 0) & ~mask
        rgb = np.where(mask[..., None], view.rgb, empty).astype(np.float32)
        weight = (mask + RING_WEIGHT * ring).astype(np.float32)
        out.append(_Template(name, c, radius, rgb, np.repeat(weight[..., None], 3, -1),
                             looks.get(name, (name,))))
    return out


@dataclass(frozen=True)
class _Scene:
    """The goal image (in I_init's frame, colours matched) and the empty table beside it."""

    image: np.ndarray
    empty: np.ndarray

    @property
    def shape(self) -> tuple[int, ...]:
        return self.image.shape

    @property
    def background_error(self) -> np.ndarray:
        return ((self.image - self.empty) ** 2).sum(-1).astype(np.float32)

    def crop(self, y0: int, y1: int, x0: int, x1: int) -> _Scene:
        return _Scene(self.image[y0:y1, x0:x1], self.empty[y0:y1, x0:x1])


def _score_map(scene: _Scene, rgb: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Per placement: the template's squared colour error over the empty table's, under the weights
    (low where the object explains the pixels that the table does not: neither a patch of plain
    table nor another object of a similar colour scores well)."""
    own = cv2.matchTemplate(scene.image, rgb, cv2.TM_SQDIFF, mask=w)
    table = cv2.matchTemplate(scene.background_error, np.ascontiguousarray(w[..., 0]), cv2.TM_CCORR)
    total = max(float(w[..., 0].sum()), 1e-6)
    return (own / total) / (table / total + RATIO_FLOOR)


def _peaks(score: np.ndarray, k: int, spacing: int) -> list[tuple[float, int, int]]:
    s = score.copy()
    out = []
    for _ in range(k):
        v, u = np.unravel_index(int(np.argmin(s)), s.shape)
        if not np.isfinite(s[v, u]):
            break
        out.append((float(s[v, u]), int(u), int(v)))
        s[max(0, v - spacing):v + spacing + 1, max(0, u - spacing):u + spacing + 1] = np.inf
    return out


def _coarse(t: _Template, half: _Scene) -> list[tuple[float, float, float, float]]:
    """Candidates (error, u, v, angle) at full-resolution origin pixels."""
    best: np.ndarray | None = None
    best_angle: np.ndarray = np.zeros(0)
    for angle in np.arange(0.0, 360.0, COARSE_STEP):
        rgb, w = t.turned(float(angle), 0.5)
        if rgb.shape[0] >= half.shape[0] or rgb.shape[1] >= half.shape[1]:
            continue
        s = _score_map(half, rgb, w)
        if best is None:
            best, best_angle = s, np.full(s.shape, angle)
        else:
            better = s < best
            best = np.where(better, s, best)
            best_angle = np.where(better, angle, best_angle)
    if best is None:
        return []
    r = (t.turned(0.0, 0.5)[0].shape[0] - 1) / 2
    return [(e, 2 * (u + r), 2 * (v + r), float(best_angle[v, u]))
            for e, u, v in _peaks(best, CANDIDATES, max(2, t.radius // 2))]


def _fine(t: _Template, image: _Scene, u0: float, v0: float, a0: float) -> tuple[float, float, float, float]:
    pad = 6
    best = (math.inf, u0, v0, a0)
    for angle in np.arange(a0 - FINE_SPAN, a0 + FINE_SPAN + 1e-9, FINE_STEP):
        rgb, w = t.turned(float(angle))
        r = t.radius
        x0, y0 = int(round(u0)) - r - pad, int(round(v0)) - r - pad
        x1, y1 = x0 + 2 * r + 1 + 2 * pad, y0 + 2 * r + 1 + 2 * pad
        if x0 < 0 or y0 < 0 or x1 > image.shape[1] or y1 > image.shape[0]:
            continue
        s = _score_map(image.crop(y0, y1, x0, x1), rgb, w)
        v, u = np.unravel_index(int(np.argmin(s)), s.shape)
        if s[v, u] < best[0]:
            du = _parabola(s[v, u - 1:u + 2]) if 0 < u < s.shape[1] - 1 else 0.0
            dv = _parabola(s[v - 1:v + 2, u]) if 0 < v < s.shape[0] - 1 else 0.0
            best = (float(s[v, u]), x0 + u + du + r, y0 + v + dv + r, float(angle))
    return best


def _parabola(y: np.ndarray) -> float:
    denom = y[0] - 2 * y[1] + y[2]
    return float(np.clip(0.5 * (y[0] - y[2]) / denom, -0.5, 0.5)) if denom > 1e-9 else 0.0


def _inliers(t: _Template, scene: _Scene, u: float, v: float, angle: float) -> float:
    """Share of the template's telling pixels (those unlike the empty table) that the goal image
    shows closer to the object than to the empty table."""
    rgb, w = t.turned(angle)
    r = t.radius
    x0, y0 = int(round(u)) - r, int(round(v)) - r
    if x0 < 0 or y0 < 0 or x0 + 2 * r + 1 > scene.shape[1] or y0 + 2 * r + 1 > scene.shape[0]:
        return 0.0
    part = scene.crop(y0, y0 + 2 * r + 1, x0, x0 + 2 * r + 1)
    to_obj = np.linalg.norm(part.image - rgb, axis=-1)
    to_table = np.linalg.norm(part.image - part.empty, axis=-1)
    telling = (w[..., 0] >= 0.5) & (np.linalg.norm(rgb - part.empty, axis=-1) > TELLING)
    if telling.sum() < 10:
        return 0.0
    agree = (to_obj + INLIER_MARGIN < to_table) & (to_obj < INLIER_DIFF)
    return float(agree[telling].mean())


def _assign(groups: dict[tuple[object, ...], list[_Template]],
            cands: dict[str, list[Candidate]]) -> dict[str, Candidate]:
    chosen: dict[str, tuple[float, float, float, float]] = {}
    for members in groups.values():
        if len(members) == 1:
            if cands[members[0].name]:
                chosen[members[0].name] = cands[members[0].name][0]
            continue
        pool = sorted({(round(c[1]), round(c[2])): c for m in members for c in cands[m.name]}.values())
        best: tuple[float, tuple[int, ...]] | None = None
        for perm in itertools.permutations(range(len(pool)), min(len(members), len(pool))):
            cost = sum(_cost_at(cands[m.name], pool[i]) for m, i in zip(members, perm, strict=False))
            if best is None or cost < best[0]:
                best = (cost, perm)
        if best is not None:
            for m, i in zip(members, best[1], strict=False):
                chosen[m.name] = pool[i]
    return chosen


def _exclusive(templates: list[_Template], chosen: dict[str, Candidate],
               cands: dict[str, list[Candidate]], stacked: set[frozenset[str]],
               agrees: Mapping[str, bool]) -> dict[str, Candidate]:
    """No two objects at one place unless one rests on the other: an object whose chosen place agrees
    with its template keeps it against one whose place does not (an object missing from the goal
    image finds its best place where another object is), and between equals the larger template
    keeps it (a small object fits inside a larger one of its colour, never the other way); the other
    takes its next candidate that is free."""
    taken: list[tuple[_Template, Candidate]] = []
    out: dict[str, Candidate] = {}
    for t in sorted(templates, key=lambda t: (not agrees.get(t.name, False),
                                              -float((t.weight[..., 0] >= 0.5).sum()))):
        if t.name not in chosen:
            continue
        options = [chosen[t.name]] + [c for c in cands[t.name] if c != chosen[t.name]]
        for c in options:
            clash = any(math.hypot(c[1] - o[1], c[2] - o[2]) < CLASH * max(t.radius, other.radius)
                        for other, o in taken if frozenset((t.name, other.name)) not in stacked)
            if not clash:
                out[t.name] = c
                taken.append((t, c))
                break
    return out


def _cost_at(cands: list[tuple[float, float, float, float]], c: tuple[float, float, float, float]) -> float:
    near = [e for e, u, v, _ in cands if math.hypot(u - c[1], v - c[2]) < 4]
    return min(near) if near else c[0] * 4 + 1e4


def match(init: TopView, empty: np.ndarray, goal: np.ndarray,
          looks: Mapping[str, tuple[object, ...]] | None = None,
          stacked: set[frozenset[str]] | None = None) -> MatchReport:
    """Find every object of ``init`` in ``goal``; ``looks`` groups objects that look alike, and
    ``stacked`` names the pairs that may share a place (one rests on or in the other)."""
    t0 = time.perf_counter()
    if goal.shape != init.rgb.shape:
        raise MatchingError(f"the goal image is {goal.shape}, the initial image {init.rgb.shape}")
    background = init.segmentation < 0
    warp, ok = register(empty, goal, background)
    aligned = _unwarp(goal, warp)
    image = normalise_colour(aligned, init.rgb, background).astype(np.float32)
    plain = empty.astype(np.float32)
    scene = _Scene(image, plain)
    half = _Scene(*(cv2.resize(a, None, fx=0.5, fy=0.5, interpolation=cv2.INTER_AREA)
                    for a in (image, plain)))
    templates = _templates(init, empty, looks or {})
    cands = {t.name: _coarse(t, half) for t in templates}
    groups: dict[tuple[object, ...], list[_Template]] = {}
    for t in templates:
        groups.setdefault(t.look, []).append(t)
    assigned = _assign(groups, cands)
    refined: dict[tuple[str, Candidate], tuple[Candidate, float]] = {}  # (name, coarse) -> fine, inliers

    def refine_at(t: _Template, c: Candidate) -> tuple[Candidate, float]:
        if (t.name, c) not in refined:
            fine = _fine(t, scene, *c[1:])
            refined[t.name, c] = fine, _inliers(t, scene, *fine[1:])
        return refined[t.name, c]

    agrees = {t.name: refine_at(t, assigned[t.name])[1] >= MIN_INLIERS
              for t in templates if t.name in assigned}
    chosen = _exclusive(templates, assigned, cands, stacked or set(), agrees)
    matches: dict[str, Match] = {}
    for name in init.names:
        x0, y0, yaw0 = init.poses[name]
        found_t = next((t for t in templates if t.name == name), None)
        if found_t is None or name not in chosen:
            matches[name] = Match(name, False, (x0, y0), yaw0, (math.nan, math.nan), math.inf, 0.0)
            continue
        (err, u, v, a), inl = refine_at(found_t, chosen[name])
        xy = init.camera.to_world(np.array([[u, v]]), init.heights[name])[0]
        yaw = float((yaw0 + math.radians(a) * init.camera.handedness() + math.pi) % (2 * math.pi) - math.pi)
        found = inl >= MIN_INLIERS
        matches[name] = Match(name, found, (float(xy[0]), float(xy[1])) if found else (x0, y0),
                              yaw if found else yaw0, (float(u), float(v)), float(err), inl)
    if not any(m.found for m in matches.values()):
        raise MatchingError("no object of the initial image was found in the goal image: the image model "
                            "redrew the scene beyond recognition; try another seed or model")
    return MatchReport(matches, warp.tolist(), ok, time.perf_counter() - t0, aligned)
