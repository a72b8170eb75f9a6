"""Pixel-mask geometry for the image critic: hulls, dilation, contact, translation, extents.

Pure numpy (and shapely for hulls) on boolean masks of one view; nothing here knows about objects,
predicates or the simulator.
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.geometry import MultiPoint

TOUCH = 2  # pixels: masks closer than this touch
DEPTH_TOL = 0.02  # metres: adjacent pixels this close in depth are in contact


def hull(mask: np.ndarray) -> np.ndarray:
    """The filled convex hull of a mask's pixels."""
    rows, cols = np.nonzero(mask)
    if len(rows) < 3:
        return mask.copy()
    shape = MultiPoint(np.column_stack([cols, rows]).astype(float)).convex_hull.buffer(0.5)
    r0, r1, c0, c1 = rows.min(), rows.max() + 1, cols.min(), cols.max() + 1
    cc, rr = np.meshgrid(np.arange(c0, c1), np.arange(r0, r1))
    out = np.zeros_like(mask)
    out[r0:r1, c0:c1] = shapely.contains_xy(shape, cc.astype(float), rr.astype(float))
    return out | mask


def dilate(mask: np.ndarray, px: int) -> np.ndarray:
    out = mask.copy()
    for _ in range(px):
        grown = out.copy()
        grown[1:] |= out[:-1]
        grown[:-1] |= out[1:]
        grown[:, 1:] |= out[:, :-1]
        grown[:, :-1] |= out[:, 1:]
        out = grown
    return out


def touch(a: np.ndarray, b: np.ndarray, depth: np.ndarray | None = None) -> bool:
    """Masks ``a`` and ``b`` are adjacent; with depth, also at about the same distance (a real
    contact, not one object seen in front of the other)."""
    near = dilate(a, TOUCH) & b
    if depth is None or not near.any():
        return bool(near.any())
    grown_b = dilate(b, TOUCH) & a
    da, db = depth[grown_b], depth[near]
    return bool(np.min(np.abs(da[:, None] - db[None, :])) < DEPTH_TOL) if da.size and db.size else False


def shift(mask: np.ndarray, dr: int, dc: int) -> np.ndarray:
    out = np.zeros_like(mask)
    h, w = mask.shape
    src = mask[max(0, -dr):h - max(0, dr), max(0, -dc):w - max(0, dc)]
    out[max(0, dr):max(0, dr) + src.shape[0], max(0, dc):max(0, dc) + src.shape[1]] = src
    return out


def best_shift(before: np.ndarray, now: np.ndarray) -> tuple[int, int]:
    """The translation (rows, columns) that lays ``before`` best over ``now`` (cross-correlation)."""
    h, w = before.shape
    fa = np.fft.rfft2(now.astype(float), s=(2 * h, 2 * w))
    fb = np.fft.rfft2(before.astype(float), s=(2 * h, 2 * w))
    corr = np.fft.irfft2(fa * np.conj(fb), s=(2 * h, 2 * w))
    r, c = np.unravel_index(int(np.argmax(corr)), corr.shape)
    return (int(r) if r < h else int(r) - 2 * h), (int(c) if c < w else int(c) - 2 * w)


Move = tuple[float, float, float, int, int]  # degrees turned about (row, column), then rows and columns


def turned(values: np.ndarray, row: float, col: float, deg: float) -> np.ndarray:
    """``values`` turned ``deg`` degrees about the pixel (``row``, ``col``), each pixel taking its
    nearest source pixel; what comes from outside the image is zero."""
    if deg == 0:
        return values.copy()
    h, w = values.shape
    rr, cc = np.mgrid[0:h, 0:w]
    t = np.radians(deg)
    sr = np.rint(row + np.cos(t) * (rr - row) + np.sin(t) * (cc - col)).astype(int)
    sc = np.rint(col - np.sin(t) * (rr - row) + np.cos(t) * (cc - col)).astype(int)
    inside = (sr >= 0) & (sr < h) & (sc >= 0) & (sc < w)
    out = np.zeros_like(values)
    out[inside] = values[sr[inside], sc[inside]]
    return out


def best_move(before: np.ndarray, now: np.ndarray, turns: tuple[float, ...]) -> Move:
    """The turn (one of ``turns``, degrees, about ``before``'s centre) and translation that lay
    ``before`` over the most of ``now``'s pixels."""
    rows, cols = np.nonzero(before)
    row, col = float(rows.mean()), float(cols.mean())
    # search in the window that holds ``now`` and ``before`` turned any way (the same translations)
    reach = int(np.ceil(np.hypot(rows - row, cols - col).max())) + 1
    now_rows, now_cols = np.nonzero(now)
    r0 = max(0, min(int(row) - reach, int(now_rows.min(initial=before.shape[0]))))
    r1 = max(int(row) + reach + 1, int(now_rows.max(initial=0)) + 1)
    c0 = max(0, min(int(col) - reach, int(now_cols.min(initial=before.shape[1]))))
    c1 = max(int(col) + reach + 1, int(now_cols.max(initial=0)) + 1)
    window, target = before[r0:r1, c0:c1], now[r0:r1, c0:c1]
    best: tuple[int, Move] | None = None
    for deg in turns:
        mask = turned(window, row - r0, col - c0, deg)
        dr, dc = best_shift(mask, target)
        score = int((shift(mask, dr, dc) & target).sum())
        if best is None or score > best[0]:
            best = score, (deg, row, col, dr, dc)
    assert best is not None, "no turns to try"
    return best[1]


def moved(values: np.ndarray, move: Move) -> np.ndarray:
    """``values`` turned and translated by ``move`` (see :func:`best_move`)."""
    deg, row, col, dr, dc = move
    return shift(turned(values, row, col, deg), dr, dc)


def rows_of(mask: np.ndarray) -> tuple[int, int] | None:
    rows = np.nonzero(mask.any(axis=1))[0]
    return (int(rows[0]), int(rows[-1])) if len(rows) else None


def spread(mask: np.ndarray) -> np.ndarray:
    """Standard deviations of a mask's pixels along its principal axes (rotation invariant)."""
    rows, cols = np.nonzero(mask)
    if len(rows) < 3:
        return np.zeros(2)
    return np.sqrt(np.maximum(np.linalg.eigvalsh(np.cov(np.stack([rows, cols]).astype(float))), 0.0))


def rectangle_sides(mask: np.ndarray, step_deg: float = 1.0) -> tuple[float, float]:
    """Side lengths (pixels, longer first) of the smallest-area rectangle around ``mask``'s pixels,
    over headings ``step_deg`` apart (0, 0 for an empty mask)."""
    rows, cols = np.nonzero(mask)
    if not len(rows):
        return 0.0, 0.0
    pts = np.column_stack([cols, rows]).astype(float)
    angles = np.radians(np.arange(0.0, 90.0, step_deg))
    u = pts @ np.stack([np.cos(angles), np.sin(angles)])  # (n, angles) along each heading
    v = pts @ np.stack([-np.sin(angles), np.cos(angles)])  # and across it
    a, b = np.ptp(u, axis=0) + 1, np.ptp(v, axis=0) + 1  # a pixel is 1 wide
    k = int(np.argmin(a * b))
    return float(max(a[k], b[k])), float(min(a[k], b[k]))


def centroid_in(mask: np.ndarray, region: np.ndarray, tol: int) -> bool:
    """The centre of ``mask``'s pixels lies in ``region``'s hull grown by ``tol`` pixels."""
    rows, cols = np.nonzero(mask)
    r, c = int(round(float(rows.mean()))), int(round(float(cols.mean())))
    return bool(dilate(hull(region), tol)[r, c])


def inward(mask: np.ndarray, region: np.ndarray) -> float:
    """How far (pixels) the centre of ``mask``'s pixels lies inside ``region``'s hull: its distance
    to the nearest pixel outside the hull; outside it, minus its distance to the nearest pixel in it."""
    rows, cols = np.nonzero(mask)
    r, c = float(rows.mean()), float(cols.mean())
    inner = hull(region)
    within = bool(inner[int(round(r)), int(round(c))])
    other = np.argwhere(~inner if within else inner)
    if not len(other):  # the hull fills the view, or is empty
        return float(max(inner.shape)) if within else -float(max(inner.shape))
    d = float(np.min(np.hypot(other[:, 0] - r, other[:, 1] - c)))
    return d if within else -d
