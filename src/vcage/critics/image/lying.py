"""How an object lies, from the views: down on a surface or not, on its side, turned over, slanted."""

from __future__ import annotations

import numpy as np

from vcage.assets.catalog import ObjectType
from vcage.critics.base import Observation, Reason, View
from vcage.critics.image.measure import (
    _heights,
    _highest,
    _inner,
    _mask,
    _max_height,
    _on_its_base,
    _open,
    _own_height,
    _peak,
    _plane,
    _relief,
    _shows_most,
    _surface,
    _type_of,
)
from vcage.critics.image.thresholds import BARE, TOP, active
from vcage.critics.masks import (
    TOUCH,
    Move,
    best_move,
    best_shift,
    dilate,
    moved,
)


def _on_its_side(obs: Observation, top: View, a: str, b: str) -> Reason | None:
    """Why ``a`` lies on its side on ``b`` instead of standing on its base (None if it does not, or
    the views cannot tell). Lying on a side, its top stands at most its longest side across above
    ``b``'s surface; standing, its own height (see :func:`_standing_and_lying`). Where the first is
    at least :data:`SIDE_GAP` lower than the second (a cup: 7 cm across, 9 cm tall), a top nearer the
    lying height than the standing one lies on its side. A tilted object (a cup leaning on its rim's
    edge) stands at least as high as the lower of the two: a cylinder tipped by an angle reaches its
    height times the cosine plus its diameter times the sine. Objects that carry on any face (cubes)
    and objects not taller than wide are not judged. An open container whose top view tells whether
    its inside shows (see :func:`_inside_fall`) is judged by that alone: a cup standing in a tilt its
    height reads as lying still shows its inside."""
    otype = _type_of(obs, a)
    before = obs.before.get(TOP)
    hb, ha = (_heights(before), _heights(top)) if before is not None else (None, None)
    if otype is None or otype.any_face or before is None or hb is None or ha is None:
        return None
    now, mb = _mask(obs, top, a), _mask(obs, before, b)
    if not now.any() or not mb.any():
        return None
    fall = _inside_fall(otype, top, now, ha) if _open(otype) else None
    if fall is not None:  # the top view tells by itself: its inside shows (standing or leaning) or not
        drop, radius = fall
        if drop >= radius:
            return None
        return Reason("lying_on_side", f"{a} shows no inside from the top (its top falls {100 * drop:.1f} cm "
                      f"to its lowest, lying on its side at most {100 * radius:.1f} cm): it lies on its side")
    standing, lying = _standing_and_lying(obs, otype, before, a)
    surface = _surface(obs, b, _peak(hb, mb))
    if standing - lying < active().SIDE_GAP or surface is None:
        return None
    high = float(np.percentile(ha[now], 95)) - surface
    if high < (standing + lying) / 2:
        return Reason("lying_on_side", f"{a}'s top is {100 * high:.1f} cm above {b}'s surface, "
                      f"{100 * standing:.1f} cm standing and {100 * lying:.1f} cm lying: it lies on its side")
    return None


def _inside_fall(otype: ObjectType, top: View, mask: np.ndarray,
                 heights: np.ndarray) -> tuple[float, float] | None:
    """How far the top of ``mask``, an open container (a cup) in the top view, falls to its lowest
    (the :data:`HOLLOW_PERCENTILE` of its inner heights), and the most it falls lying on its side;
    None where the view cannot tell. Standing on its base, or leaning, it shows its inside from the
    top: its inner pixels reach down from its rim by about its depth. Lying on its side it shows its
    outer wall, whose curve falls from its top to its outline by at most its radius (half its width
    at its largest scale). Judged for a container deep enough that standing it reads far more (its
    depth at its smallest scale at least :data:`DEEP` times that radius: a cup, a mug, a pen holder;
    not a bowl, a basket or a box), where its top view covers at least what it covers standing (see
    :func:`_shows_most`): a cup mostly hidden may show only its wall. Unlike the heights of
    :func:`_on_its_side`, this needs no height seen before (a cup fused into the basket at the start,
    and carried so, never stood on the table)."""
    lo, hi = otype.scale_range
    radius = min(otype.size[0], otype.size[1]) / 2 * hi
    depth = (otype.size[2] - otype.placements[0].pos[2]) * lo
    if depth < active().DEEP * radius or not _shows_most(otype, top, mask):
        return None
    lowest = float(np.percentile(heights[_inner(mask)], active().HOLLOW_PERCENTILE))
    drop = _highest(heights, mask, rim=True) - lowest
    return drop, radius


def _standing_and_lying(obs: Observation, otype: ObjectType, before: View, a: str) -> tuple[float, float]:
    """How high ``a``'s top stands above what it rests on, standing on its base and lying on a side
    (its longest side across). Where the top view saw ``a`` stand on its base on the table before
    the subtask (its top-view area within :data:`FOOTPRINT` of its type's, its own height known, see
    :func:`_own_height`, and within its type's heights), at the scale that height gives; otherwise
    (it lay on its side already, leaned, or stood on something) the lowest standing and the highest
    lying height its type's scales allow."""
    lo, hi = otype.scale_range
    across = max(otype.size[0], otype.size[1])
    own = _own_height(obs, a, outline=True)
    tol = active().UPRIGHT_TOL
    if (own is not None and _on_its_base(otype, before, _mask(obs, before, a))
            and otype.size[2] * lo - tol <= own <= otype.size[2] * hi + tol):
        return own, across * own / otype.size[2]
    return otype.size[2] * lo, across * hi


def _not_down(obs: Observation, top: View, a: str, surface: float | None, floor: float, where: str,
              skip: tuple[str, ...], standing: bool = False, any_way_up: bool = False,
              slope: float = 0.0) -> Reason | None:
    """Why ``a`` cannot rest on a support whose surface lies ``surface`` above the table (``where``
    names it), from the top view's heights; None if they allow it (or cannot tell). Without a known
    surface only clutter higher than ``floor`` counts (see :func:`_landed_on_other`). ``standing``:
    ``a`` stands there as it stood before (put down by the hand), so its top can be no higher than
    its type reaches above the surface either (tipped onto a side, or propped on something, it
    stands taller). ``any_way_up``: ``a`` may rest on any face (in a container), so its longest side
    bounds how far its top stands above the surface. ``slope``: the surface leans so far (radians),
    and ``a`` with it (see :func:`_max_height`)."""
    before = obs.before.get(TOP)
    hb, ha = (_heights(before), _heights(top)) if before is not None else (None, None)
    ma = _mask(obs, top, a)
    if before is None or hb is None or ha is None or not ma.any():
        return None
    height = _max_height(obs, a, any_way_up, slope)
    too_tall = None  # said after the clutter under ``a``, which says more
    if surface is not None and height is not None:
        above = float(ha[ma].min()) - height - surface
        if above > active().HEIGHT_TOL:
            return Reason("too_high",
                          f"{a} stands {100 * above:.1f} cm higher than resting on {where} allows")
        taller = _highest(ha, ma, rim=_open(_type_of(obs, a))) - height - surface
        if standing and taller > active().TOP_TOL:
            too_tall = Reason("too_tall", f"{a}'s top is {100 * taller:.1f} cm higher than {a} standing on "
                              f"{where} reaches")
    surface = floor if surface is None else surface
    for i, c in enumerate(obs.labels):
        was = before.segmentation == i
        if c in skip or not was.any():
            continue
        now = top.segmentation == i
        pushed = now.any() and (now & dilate(was, TOUCH)).sum() < active().STILL * now.sum()
        move: Move = (0.0, 0.0, 0.0, *(best_shift(was, now) if pushed else (0, 0)))  # pushed: follow it
        outline = moved(was, move)
        bare_a = ma & ~dilate(now, 1)  # what of ``a`` does not border what shows of ``c``
        under = outline & bare_a
        # where ``c`` stayed, ``a`` hides of it what it no longer shows: nudged a pixel or two (not
        # followed), it still shows all of itself, and the sliver of its outline under ``a`` is not ``c``
        hidden = int(under.sum()) if pushed else min(int(under.sum()), int(was.sum()) - int(now.sum()))
        # it may have turned as it went: a slid outline overhangs it
        if pushed and hidden >= active().UNDER_PX:
            move = best_move(was, now, active().TURNS)
            outline = moved(was, move)
            under = outline & bare_a
            hidden = int(under.sum())
        if hidden < active().UNDER_PX:
            continue
        beside = outline & ~dilate(ma, 1)  # where ``c`` would show if it still lay under ``a``
        if (beside & (top.segmentation == BARE)).sum() > beside.sum() / 2:
            continue  # the table shows there: ``c`` is gone (knocked off, out of sight)
        rise = float(np.median(moved(np.where(was, hb, 0.0), move)[under])) - surface
        t = active()
        if rise > t.SUPPORT_TOL or (rise > t.THIN_SUPPORT and under.sum() >= t.MIN_OVERLAP * ma.sum()):
            return Reason("on_other_object",
                          f"{a} lies over {c}, whose top is {100 * rise:.1f} cm above {where}")
    return too_tall


def _turned_over(obs: Observation, top: View, a: str) -> Reason | None:
    """Why ``a`` lies turned over (None if its top kept its shape, or the views cannot tell): it stood
    on its base before the subtask (see :data:`FOOTPRINT`) with a curved top (at least :data:`CURVED`
    from a plane), and its top is now nearly flat (under :data:`FLAT_TOP` of that), as a mouse on its
    back shows its flat underside; or its type declares a domed top (``top_relief``) and its top is
    far flatter (under :data:`TYPE_FLAT` of that), whatever it showed before (a mouse tipped over at a
    slant shows a flat face and part of its dome: see :func:`_slanted_dome`). Containers are left out:
    how much of their inside shows changes with what stands around them; so are cubes, which rest on
    any face."""
    otype = _type_of(obs, a)
    before = obs.before.get(TOP)
    if otype is None or before is None or before.pixel_size is None or _open(otype) or otype.any_face:
        return None
    now = _relief(top, _mask(obs, top, a))
    share = active().TYPE_FLAT
    flat = share * otype.top_relief * otype.scale_range[0]
    why = _flatter_than_before(obs, a, otype, before, now)
    if why is None and now is not None and now < flat:
        return Reason("turned_over", f"{a}'s top is flat ({1000 * now:.1f} mm from a plane; {otype.name} "
                      f"standing shows at least {1000 * flat / share:.1f} mm): it lies turned over")
    return why


def _slanted_dome(obs: Observation, top: View, a: str, b: str) -> Reason | None:
    """Why ``a``, of a type that declares a domed top (``top_relief``: a mouse), does not rest on its
    base on ``b`` (None if it may, or the view cannot tell): the plane fitting its top's heights
    slopes by more than :data:`DOME_SLOPE` beyond ``b``'s surface. Standing on its base a dome's plane
    lies as level as what it stands on; turned over at a slant it shows its flat underside tilted (and
    part of its dome, so neither its relief nor its bend need change much). Judged where the top view
    shows at least what it covers standing (see :func:`_shows_most`): a dome mostly hidden may show
    only a slope of its side."""
    otype, btype = _type_of(obs, a), _type_of(obs, b)
    if otype is None or not otype.top_relief or top.pixel_size is None:
        return None
    mask = _mask(obs, top, a)
    fit = _plane(top, mask)
    if fit is None or not _shows_most(otype, top, mask):
        return None
    ramp = btype.placements[0].slope if btype is not None and btype.placements else 0.0
    bound = float(np.tan(ramp)) + active().DOME_SLOPE
    if fit[2] <= bound:
        return None
    return Reason("tilted", f"{a}'s domed top slopes {fit[2]:.2f} (rise over run), where standing on its "
                  f"base on {b} it slopes at most {bound:.2f}: it lies tipped over at a slant")


def _flatter_than_before(obs: Observation, a: str, otype: ObjectType, before: View,
                         now: float | None) -> Reason | None:
    """The first reason of :func:`_turned_over` (``now``: the relief of ``a``'s top after)."""
    mask = _mask(obs, before, a)
    if not _on_its_base(otype, before, mask):
        return None  # not standing on its base before (a tilted block shows a side: two faces, no plane)
    was = _relief(before, mask)
    if was is None or now is None or was < active().CURVED:
        return None
    if now < active().FLAT_TOP * was:
        return Reason("turned_over", f"{a}'s top is flat now ({1000 * now:.1f} mm from a plane, "
                      f"{1000 * was:.1f} mm before): it lies turned over")
    return None
