"""What rests on what: ``on``, ``inside`` (with its drawer case), ``stacked``, and their front-view
and top-view tests."""

from __future__ import annotations

import numpy as np

from vcage.critics.base import Observation, Reason, View
from vcage.critics.image.drawers import _in_drawer
from vcage.critics.image.lying import _not_down, _on_its_side, _slanted_dome, _turned_over
from vcage.critics.image.measure import (
    _covered,
    _heights,
    _highest,
    _inner,
    _lower_end,
    _mask,
    _outline,
    _own_height,
    _peak,
    _plane,
    _surface,
    _type_of,
)
from vcage.critics.image.thresholds import FRONT, TOP, active
from vcage.critics.masks import (
    centroid_in,
    hull,
    inward,
    rows_of,
    touch,
)


def _rests_on(obs: Observation, a: str, b: str, inside: bool) -> tuple[bool, str]:
    top = obs.after.get(TOP)
    front = obs.after.get(FRONT)
    if top is None or front is None:
        return False, Reason("missing_view", "the top and front views are needed")
    ma, mb = _mask(obs, top, a), _outline(obs, top, b)  # ``a`` may hide part of ``b`` now
    if not ma.any():
        return False, Reason("not_visible", f"{a} is not visible from the top")
    if _covered(obs, top, b):  # from the top ``b`` is (mostly) hidden: where it is, the front view says
        side = None if inside else _on_its_side(obs, top, a, b)  # a cup lying across a coaster hides it
        return (False, side) if side is not None else _front_support(obs, front, a, b)
    if not mb.any():
        return False, Reason("not_visible", f"{b} is not visible from the top")
    # which is smaller by hulls, not pixels: where ``a`` hid the middle of ``b`` before and hides it
    # now, ``b``'s outline is a ring with fewer pixels than ``a`` though ``b`` is the larger
    hull_a, hull_b = hull(ma), hull(mb)
    small, big = (ma, hull_b) if hull_a.sum() <= hull_b.sum() else (mb, hull_a)
    overlap = float((small & big).sum() / small.sum())
    btype = _type_of(obs, b)
    if overlap < active().MIN_OVERLAP and not (btype is not None and btype.any_face):
        return False, Reason("not_over_target", f"only {overlap:.0%} of {a} overlaps {b} from the top")
    if not centroid_in(ma, mb, active().CENTRE_TOL):
        return False, Reason("not_over_target", f"the centre of {a} is not over {b} from the top")
    # in a container an object may lie any way up; on a surface, turned over it does not rest on its base
    other = _landed_on_other(obs, top, a, b, inside) or (
        None if inside else _turned_over(obs, top, a) or _slanted_dome(obs, top, a, b)
        or _on_its_side(obs, top, a, b))
    if other is not None:
        return False, other
    fa, fb = rows_of(_mask(obs, front, a)), rows_of(_mask(obs, front, b) | _mask(obs, front, a))
    if fa is not None and fb is not None:
        a_bottom = fa[1]
        if a_bottom < fb[0] - active().ROW_TOL and not inside:
            return False, Reason("floating", f"{a} floats above {b} in the front view")
        if a_bottom > fb[1] + active().ROW_TOL:
            return False, Reason("below_target", f"{a} is below {b} in the front view")
    return True, f"{overlap:.0%} overlap from the top"


def _landed_on_other(obs: Observation, top: View, a: str, b: str, inside: bool) -> Reason | None:
    """Why ``a`` cannot rest on (in) ``b`` from the heights of the top view (None if they allow it).

    - ``a`` stands too high: an object resting on ``b`` has the top of its own axis (whose height
      its lowest pixel cannot exceed) at most its height above its resting face, which lies on
      ``b``'s surface (on a leaning surface, see :func:`_max_height`). In ``b`` it may lie any way
      up (the oracle asks only that its lowest point be below the rim): where its top-view area
      changed as a turned object's does (see :data:`AREA_RATIO`), or its top slopes more than
      :data:`LEVEL` (it leans), its longest side takes the place of its height above the rim.
    - ``a`` rests on ``b``'s rim (see :func:`_on_rim`).
    - ``a`` lies over another object ``c`` whose top stood more than :data:`SUPPORT_TOL` above that
      surface (:data:`THIN_SUPPORT` under most of ``a``'s outline): before the subtask the top view
      showed ``c`` where ``a`` is seen now, and ``c`` is still there (followed if it was pushed,
      turned as well as slid, see :data:`TURNS`; one that stayed shows less of itself than before,
      not a neighbour nudged against ``a``; one the table shows through where it stood, beside
      ``a``, is gone), so ``a`` lies above ``c`` and cannot be down on ``b``.
      Not asked of ``a`` leaning in ``b``: it may lean against ``c`` standing in ``b`` (a loaf on
      a cup that stood in the basket, its lower end on the floor); its lower end decides.
    """
    before = obs.before.get(TOP)
    hb = _heights(before) if before is not None else None
    if before is None or hb is None:
        return None
    mb = _mask(obs, before, b)
    if not mb.any():
        return None
    rim = _peak(hb, mb)
    surface = rim if inside else _surface(obs, b, rim)
    btype = _type_of(obs, b)
    slope = btype.placements[0].slope if btype is not None and btype.placements and not inside else 0.0
    ma = _mask(obs, top, a)
    was, now = int(_mask(obs, before, a).sum()), int(ma.sum())
    turned = was > 0 and not active().AREA_RATIO[0] <= now / was <= active().AREA_RATIO[1]
    fit = _plane(top, ma) if inside and not turned else None
    leaning = fit is not None and fit[2] > active().LEVEL
    on_rim = _on_rim(obs, top, a, b, fit if leaning else None) if inside and not turned else None
    # leaning, ``a`` may rest against what stands in ``b``: its lower end decides (``on_rim``)
    skip = tuple(obs.labels) if leaning else (a, b)
    return on_rim or _not_down(obs, top, a, surface, rim, f"{b}'s {'rim' if inside else 'surface'}",
                               skip, standing=True, any_way_up=inside and (turned or leaning), slope=slope)


def _on_rim(obs: Observation, top: View, a: str, b: str,
            lean: tuple[np.ndarray, np.ndarray, float] | None = None) -> Reason | None:
    """Why ``a`` lies on ``b``'s rim rather than in it (None if it does not, or the views cannot
    tell). ``a`` lies as it lay before (its top-view area kept), so its underside is its own height
    under its top; before the subtask ``a`` stood on the table (the outline around it there), where
    its top was that height. An underside less than :data:`RIM_GAP` under the rim rests on it (a
    loaf bridging a basket), where the oracle wants it more than its contact tolerance under. The
    rim's height is read from all of ``b``'s pixels (at the :data:`RIM_PERCENTILE`): a thin wall
    may be one pixel wide, with no inner pixel. ``lean``: the plane fitting ``a``'s top (see
    :func:`_plane`) where its slope says ``a`` leans (a loaf with one end on the floor and the other
    against the rim): its lowest point lies under the top's lower end (see :func:`_lower_end`), and
    ``a`` is thicker upright through a point by the slope's secant."""
    before = obs.before.get(TOP)
    hb, ha = (_heights(before), _heights(top)) if before is not None else (None, None)
    if before is None or hb is None or ha is None:
        return None
    now, mb = _mask(obs, top, a), _mask(obs, before, b)
    own = _own_height(obs, a)
    if own is None or not now.any() or not mb.any():
        return None
    rim = float(np.percentile(hb[mb], active().RIM_PERCENTILE))
    if lean is not None:
        heights, plane, slope = lean
        low_end = float(np.percentile(heights[_lower_end(plane)], 95))
        under = rim - (low_end - own * float(np.hypot(1.0, slope)))
    else:
        under = rim - (_highest(ha, now) - own)
    if under < active().RIM_GAP:
        where = f"{100 * under:.1f} cm under" if under >= 0 else f"{-100 * under:.1f} cm above"
        return Reason("on_rim", f"{a}'s underside is {where} {b}'s rim: it rests on the rim or on something, "
                      f"not down in {b}")
    return None


def _front_support(obs: Observation, front: View, a: str, b: str) -> tuple[bool, str]:
    """In the front view ``a`` lies above ``b``, over its columns, touching it at the same depth."""
    fa, fb = _mask(obs, front, a), _mask(obs, front, b)
    if not fa.any() or not fb.any():
        return False, Reason("not_visible", f"{b} is hidden from the top and {a} or {b} from the front")
    ca, cb = np.nonzero(fa.any(axis=0))[0], np.nonzero(fb.any(axis=0))[0]
    shared = min(ca[-1], cb[-1]) - max(ca[0], cb[0]) + 1
    if shared < active().MIN_OVERLAP * min(len(ca), len(cb)):
        return False, Reason("not_over_target", f"{a} is not over {b} in the front view")
    if np.nonzero(fa)[0].mean() >= np.nonzero(fb)[0].mean() or not touch(fa, fb, front.depth):
        return False, Reason("not_resting", f"{a} does not rest on {b} in the front view")
    return True, f"{b} is hidden from the top; {a} rests on it in the front view"


def _on(obs: Observation, a: str, b: str) -> tuple[bool, str]:
    return _rests_on(obs, a, b, inside=False)


def _inside(obs: Observation, a: str, b: str) -> tuple[bool, str]:
    ok, why = _rests_on(obs, a, b, inside=True)
    otype = _type_of(obs, b)
    drawer = next((p for p in otype.placements if p.kind == "in" and p.joint), None) if otype else None
    if not ok:
        return ok, why
    if drawer is None:
        off = _off_centre(obs, a, b)
        return (False, off) if off is not None else (ok, why)
    return _in_drawer(obs, a, b, drawer)


def _off_centre(obs: Observation, a: str, b: str) -> Reason | None:
    """Why ``a`` lies too near ``b``'s outline, in the top view after the subtask, to be in ``b``
    (None if it does not, or the views or types cannot tell). The oracle wants ``a``'s centre of
    mass over ``b``'s region, which lies in from ``b``'s outline by at least ``b``'s size less the
    region (its narrower margin, at ``b``'s smallest scale). Lying level within ``b``'s walls, ``a``
    keeps its centre at least half its smallest side (at its smallest scale) in from them: however
    turned, it spans that much on either side. A loaf fused into the basket's wall and dragged out
    with it lies across the wall, its centre 1-3 cm in from the outline, where loaves the oracle
    counts in lie 4 cm and more in (Vanilla rollouts). Leaning (its top slopes more than
    :data:`LEVEL`), ``a`` may rest against the rim with its upper end beyond it: there its lower end
    (see :func:`_lower_end`), which rests on ``b``'s floor, must lie over the region."""
    top = obs.after.get(TOP)
    atype, btype = _type_of(obs, a), _type_of(obs, b)
    if top is None or top.pixel_size is None or atype is None or btype is None:
        return None
    place = next((p for p in btype.placements if p.kind == "in"), None)
    ma, mb = _mask(obs, top, a), _outline(obs, top, b)
    if place is None or not ma.any() or not mb.any():
        return None
    margin = min(btype.size[0] / 2 - place.half_size[0], btype.size[1] / 2 - place.half_size[1])
    need = margin * btype.scale_range[0]
    part, what = ma, f"{a}'s centre"
    fit = _plane(top, ma)
    if fit is not None and fit[2] > active().LEVEL:
        plane = fit[1]
        part = np.zeros_like(ma)
        part[_inner(ma)] = _lower_end(plane)
        what = f"the centre of {a}'s lower end"
    else:
        need = max(need, min(atype.size) * atype.scale_range[0] / 2)
    depth = inward(part, mb) * top.pixel_size
    if depth >= need:
        return None
    where = f"{100 * depth:.1f} cm in from" if depth >= 0 else f"{-100 * depth:.1f} cm outside"
    return Reason("across_wall", f"{what} lies {where} {b}'s outline, where in {b} it would lie at least "
                  f"{100 * need:.1f} cm in: it lies across {b}'s wall or outside it")


def _stacked(obs: Observation, *objs: str) -> tuple[bool, str]:
    for lower, upper in zip(objs, objs[1:], strict=False):
        ok, why = _on(obs, upper, lower)
        if not ok:
            return ok, why
    return True, "stacked"
