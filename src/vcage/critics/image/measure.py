"""What the image critic measures in a view: an object's mask and outline, heights from the top
view's depth, its top's plane and relief, where it is highest, and what its type says of it."""

from __future__ import annotations

import numpy as np

from vcage.assets.catalog import CATALOG, ObjectType
from vcage.critics.base import Observation, View
from vcage.critics.image.thresholds import BARE, ROBOT, TOP, active
from vcage.critics.masks import (
    TOUCH,
    best_shift,
    dilate,
    hull,
    shift,
)


def _type_of(obs: Observation, name: str) -> ObjectType | None:
    """``name``'s catalog type, as the plan gives it (None if it does not, or names no catalog type)."""
    type_name = obs.types.get(name)
    return CATALOG.get(type_name) if type_name is not None and type_name in CATALOG else None


def _mask(obs: Observation, view: View, name: str) -> np.ndarray:
    return view.segmentation == obs.labels.index(name)


def _outline(obs: Observation, view: View, name: str) -> np.ndarray:
    """``name``'s top-view outline now, including what is hidden now (e.g. under an object put on
    it): its visible pixels and its outline before the subtask, moved to where it is now."""
    now = _mask(obs, view, name)
    before_view = obs.before.get(TOP)
    if before_view is None:
        return now
    before = _mask(obs, before_view, name)
    if not before.any() or not now.any():
        return now | before
    if (now & dilate(before, TOUCH)).sum() >= active().STILL * now.sum():  # it did not move
        return now | before
    return now | shift(before, *best_shift(before, now))


def _own_height(obs: Observation, a: str, outline: bool = False) -> float | None:
    """``a``'s own height: its highest point before the subtask, where the top view (with depth) saw
    it standing on the table (the ring of pixels around it at the table's height); None if it did not
    (it stood on something, or nothing around it shows). ``outline``: its outline's pixels count too
    (an open container's rim, see :func:`_highest`)."""
    before = obs.before.get(TOP)
    hb = _heights(before) if before is not None else None
    if before is None or hb is None:
        return None
    was = _mask(obs, before, a)
    ring = dilate(was, 2) & ~dilate(was, 1) & (before.segmentation == BARE)
    if not was.any() or ring.sum() < active().UNDER_PX or float(np.median(hb[ring])) > active().HEIGHT_TOL:
        return None
    return _highest(hb, was, rim=outline)


def _lower_end(plane: np.ndarray) -> np.ndarray:
    """Which of a leaning object's inner pixels make its lower end: the quarter of them lowest on the
    plane fitting its top (``plane``: that plane's heights at them, see :func:`_plane`)."""
    return plane <= np.percentile(plane, 25)


def _top_heights(view: View, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The heights of ``mask``'s inner pixels in an orthographic view with depth and their rows and
    columns about their mean; None with fewer than :data:`MIN_RELIEF_PX` of them."""
    heights, inner = _heights(view), _inner(mask)
    if heights is None or view.pixel_size is None or inner.sum() < active().MIN_RELIEF_PX:
        return None
    rows, cols = np.nonzero(inner)
    return heights[inner], rows - rows.mean(), cols - cols.mean()


def _plane(view: View, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray, float] | None:
    """The plane that fits the heights of ``mask``'s inner pixels best (see :func:`_top_heights`):
    those heights, the plane's at the same pixels, and its slope (rise over run)."""
    top = _top_heights(view, mask)
    if top is None or view.pixel_size is None:
        return None
    heights, r, c = top
    design = np.column_stack([r, c, np.ones_like(r)])
    coef, *_ = np.linalg.lstsq(design, heights, rcond=None)
    return heights, design @ coef, float(np.hypot(coef[0], coef[1]) / view.pixel_size)


def _relief(view: View, mask: np.ndarray) -> float | None:
    """How far (RMS, metres) the heights of ``mask``'s inner pixels lie from the plane that fits them
    best: a dome's top lies far from any plane, a flat face on it (tilted or not)."""
    fit = _plane(view, mask)
    return None if fit is None else float(np.sqrt(np.mean((fit[1] - fit[0]) ** 2)))


def _on_its_base(otype: ObjectType, view: View, mask: np.ndarray) -> bool:
    """Whether ``mask``, an object of type ``otype`` in an orthographic view, covers what it covers
    standing on its base: between the :data:`FOOTPRINT` shares of its type's footprint."""
    if view.pixel_size is None:
        return False
    lo, hi = otype.scale_range
    share = mask.sum() * view.pixel_size ** 2 / (otype.size[0] * otype.size[1])
    return bool(active().FOOTPRINT[0] * lo ** 2 <= share <= active().FOOTPRINT[1] * hi ** 2)


def _shows_most(otype: ObjectType, view: View, mask: np.ndarray) -> bool:
    """Whether ``mask``, an object of type ``otype`` in an orthographic view, covers at least what it
    covers standing on its base (the lower :data:`FOOTPRINT` share of its footprint at its smallest
    scale): not mostly hidden."""
    if view.pixel_size is None:
        return False
    footprint = otype.size[0] * otype.size[1] * otype.scale_range[0] ** 2
    return bool(mask.sum() * view.pixel_size ** 2 >= active().FOOTPRINT[0] * footprint)


def _surface(obs: Observation, b: str, top: float) -> float | None:
    """Height of ``b``'s placement surface above the table, from its highest point ``top`` and its
    type (the surface lies below the top by the type's height above it, at the smallest scale)."""
    otype = _type_of(obs, b)
    if otype is None or not otype.placements:
        return None
    return top - (otype.size[2] - otype.placements[0].pos[2]) * otype.scale_range[0]


def _max_height(obs: Observation, a: str, any_way_up: bool = False, slope: float = 0.0) -> float | None:
    """How high ``a`` reaches above the point of its support's surface where it rests, at the largest
    scale of its type: its height above its resting face (``any_way_up``: above whichever face it
    rests on, its longest side); on a surface that leans by ``slope`` radians (a stand's ramp), its
    base tilts with it, its longest side across rising up the ramp (a phone: 6.2 cm at the largest
    scale on the stand's 0.35 rad; standing on an edge in the slot, 6-8 cm and more)."""
    otype = _type_of(obs, a)
    if otype is None:
        return None
    if any_way_up:
        return max(otype.size) * otype.scale_range[1]
    across = max(otype.size[0], otype.size[1])
    return (across * float(np.sin(slope)) + otype.size[2] * float(np.cos(slope))) * otype.scale_range[1]


def _covered(obs: Observation, top: View, b: str) -> bool:
    """``b`` was visible from the top before the subtask and is now hidden (under another object):
    entirely, or mostly and moved; either way its outline from before may not say where it is."""
    before = obs.before.get(TOP)
    if before is None:
        return False
    was, now = _mask(obs, before, b), _mask(obs, top, b)
    if now.sum() >= active().COVERED * was.sum():
        return False
    return not now.any() or (now & dilate(was, TOUCH)).sum() < active().STILL * now.sum()


def _touch_depth(view: View) -> np.ndarray | None:
    """The depth ``touch`` compares: a perspective view's. The top view's depth is height, and a hand
    holding an object from above stands higher than the object it holds, so there contact is judged
    from the outlines alone."""
    return view.depth if view.pixel_size is None else None


def _heights(view: View) -> np.ndarray | None:
    """Heights above the table of what each pixel of an orthographic view with depth sees."""
    if view.depth is None or view.pixel_size is None or not np.any(view.segmentation == BARE):
        return None
    return float(np.median(view.depth[view.segmentation == BARE])) - view.depth


def _highest(heights: np.ndarray, mask: np.ndarray, rim: bool = False) -> float:
    """The highest point of ``mask`` in a top view's ``heights``, read inside its outline (see
    :func:`_inner`) at the 95th percentile, so that a few stray pixels do not set it. ``rim``: the
    outline's pixels (their median) count too: an open container's highest point is its rim, one or
    two pixels wide at its outline, around a floor seen from above (a silhouette pixel's depth alone
    may be far off)."""
    high = float(np.percentile(heights[_inner(mask)], 95))
    edge = mask & dilate(~mask, 1)
    return max(high, float(np.median(heights[edge]))) if rim and edge.any() else high


def _open(otype: ObjectType | None) -> bool:
    """Whether objects of type ``otype`` hold things inside them (a cup, a basket: seen from above,
    their inside shows)."""
    return otype is not None and any(p.kind == "in" for p in otype.placements)


def _inner(mask: np.ndarray) -> np.ndarray:
    """``mask`` without its outline (all of it, if nothing is left): a pixel's depth at a silhouette
    can be far off (one at 0.25 m above the table on a 9 cm clock was seen), so an object's highest
    point is read inside it."""
    inner = mask & ~dilate(~mask, 1)
    return inner if inner.any() else mask


def _peak(heights: np.ndarray, mask: np.ndarray) -> float:
    """The highest point inside ``mask``'s outline (see :func:`_inner`) in a top view's ``heights``,
    where a neighbouring pixel inside comes within :data:`SPIKE` of it: the top of a button, a rim
    or a surface, not a lone stray reading above it."""
    inner = _inner(mask)
    h = np.where(inner, heights, -np.inf)
    padded = np.pad(h, 1, constant_values=-np.inf)
    rows, cols = h.shape
    around = np.max([padded[1 + dy:1 + dy + rows, 1 + dx:1 + dx + cols]
                     for dy in (-1, 0, 1) for dx in (-1, 0, 1) if dy or dx], axis=0)
    kept = inner & (around >= h - active().SPIKE)
    return float(h[kept if kept.any() else inner].max())


def _top_band(heights: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """``mask``'s top in a top view's ``heights``: its pixels within :data:`TOP_BAND` of its highest
    point (see :func:`_peak`), where a button or lever is."""
    return mask & (heights >= _peak(heights, mask) - active().TOP_BAND)


def _hidden(view: View, mask: np.ndarray) -> int:
    """Robot pixels on or around ``mask``'s hull: about as much of it as the robot can hide."""
    if not mask.any():
        return 0
    return int(((view.segmentation == ROBOT) & dilate(hull(mask), TOUCH + 1)).sum())


def _scale(otype: ObjectType, heights: np.ndarray, mask: np.ndarray) -> float:
    """An object's scale from its top (the 95th percentile of its inner heights: a stray pixel's depth
    can be far off) over its type's height, within the type's scale range."""
    top = _highest(heights, mask)
    return float(np.clip(top / otype.size[2], *otype.scale_range))
