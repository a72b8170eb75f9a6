"""Where and how an object stands: ``upright``, ``on_table``, ``left_of``/``right_of``, ``near``,
``lifted``, ``facing``, ``hanging``."""

from __future__ import annotations

import numpy as np

from vcage.critics.base import Observation, Reason, View
from vcage.critics.image.lying import _not_down
from vcage.critics.image.measure import (
    _heights,
    _hidden,
    _highest,
    _mask,
    _max_height,
    _open,
    _top_band,
    _type_of,
)
from vcage.critics.image.press import _released
from vcage.critics.image.thresholds import FRONT, TOP, active
from vcage.critics.masks import (
    hull,
    rows_of,
    spread,
    touch,
)


def _upright(obs: Observation, x: str) -> tuple[bool, str]:
    """The orthographic top view sees an object's outline at its true size wherever it stands:
    tipping changes its area or its shape; the robot can only hide part of it."""
    before, after = obs.before.get(TOP), obs.after.get(TOP)
    fb, fa = obs.before.get(FRONT), obs.after.get(FRONT)
    if before is None or after is None or fb is None or fa is None:
        return False, Reason("missing_view", "the top and front views before and after are needed")
    mb, ma = _mask(obs, before, x), _mask(obs, after, x)
    hid_b, hid_a = _hidden(before, mb), _hidden(after, ma)
    area_b, area_a = int(mb.sum()), int(ma.sum())
    if area_b:  # the robot hides at most about the pixels it covers around the outline
        low, high = active().AREA_RATIO
        if area_a > high * (area_b + hid_b) or area_a + hid_a < low * area_b:
            return False, Reason("area_changed",
                                 f"{x}'s top-view area changed by x{area_a / area_b:.2f} (tipped over?)")
        if not hid_a and not hid_b and area_a:
            axes = spread(ma)[-1] / max(1e-9, spread(mb)[-1])
            if not 1 / active().SHAPE_RATIO <= axes <= active().SHAPE_RATIO:
                return False, Reason("shape_changed",
                                     f"{x}'s top-view outline stretched by x{axes:.2f} (tipped over?)")
    hb, ha = _heights(before), _heights(after)
    if hb is not None and ha is not None and mb.any() and ma.any():  # its highest point, from the top
        was, now = (_highest(h, m) for h, m in ((hb, mb), (ha, ma)))
        if now < active().HEIGHT_RATIO * was:
            return False, Reason("lower_than_before", f"{x}'s top stands x{now / max(was, 1e-9):.2f} as high "
                                 "as before (tipped over?)")
        off = _off_height(obs, after, x, now) or _tipped_axis(obs, after, x)
        if off is not None:
            return False, off
        return True, "upright"
    # without the top view's depth, its height in the front view (which a thin object turned about
    # the vertical changes too: a board's plate seen edge-on, its top edge runs away from the camera)
    rb, ra = rows_of(_mask(obs, fb, x)), rows_of(_mask(obs, fa, x))
    if rb and ra and (ra[1] - ra[0] + 1) < active().HEIGHT_RATIO * (rb[1] - rb[0] + 1):
        return False, Reason("lower_than_before",
                             f"{x} looks lower in the front view than before (tipped over?)")
    return True, "upright"


def _off_height(obs: Observation, top: View, x: str, high: float) -> Reason | None:
    """Why ``x``, whose highest point stands ``high`` above the table, cannot stand upright on the
    table (None if it can, or its type cannot tell): standing on its base its top is at most its
    type's height at the largest scale (plus :data:`UPRIGHT_TOL`); higher, it stands tipped on a side
    wider than its base is tall, unless it rests on another object. (Lower says little: a small
    button on a dome is too few pixels for the top view's highest reading.) Containers are left
    out: from the top a hollow one shows its inside."""
    otype = _type_of(obs, x)
    if otype is None or _open(otype):
        return None
    if high > otype.size[2] * otype.scale_range[1] + active().UPRIGHT_TOL \
            and _not_down(obs, top, x, None, 0.0, "the table", (x,)) is None:
        return Reason("too_tall", f"{x}'s top is {100 * high:.1f} cm above the table, higher than {x} "
                      "standing reaches (tipped?)")
    return None


def _tipped_axis(obs: Observation, top: View, x: str) -> Reason | None:
    """Why ``x`` stands tilted by more than :data:`UPRIGHT_TILT` (None if it does not, or the view or
    its type cannot tell), from where its top lies over its base. Only for a type with a round base
    (size x equal to size y) whose press point lies on its axis at its top (a bell's button): upright,
    that point lies over the centre of the base, which the orthographic top view sees as the centre
    of ``x``'s outline; tilted by an angle, it lies off it by its height times the sine (at least
    1.1 cm for a bell at 0.2 rad). Left alone where the outline shows less than :data:`WHOLE_BASE`
    of the base's disc, or the top is not a button's patch (see :data:`BUTTON_PX`). What it judges
    is how ``x`` stands, not how it came to: a bell left leaning on a neighbour it was fused with
    before the subtask stands tilted after it too."""
    otype = _type_of(obs, x)
    heights = _heights(top)
    if otype is None or heights is None or top.pixel_size is None or otype.size[0] != otype.size[1]:
        return None
    point = next((p for p in otype.functional_points if p.joint), None)
    if point is None or point.pos[:2] != (0, 0) or point.pos[2] != otype.size[2]:
        return None
    mask = _mask(obs, top, x)
    if not mask.any():
        return None
    lo = otype.scale_range[0]
    outline = hull(mask)
    if outline.sum() * top.pixel_size ** 2 < active().WHOLE_BASE * np.pi * (otype.size[0] / 2 * lo) ** 2:
        return None
    patch = _top_band(heights, mask)
    if not active().BUTTON_PX[0] <= patch.sum() <= active().BUTTON_PX[1]:
        return None
    (r, c), (rc, cc) = np.argwhere(patch).mean(axis=0), np.argwhere(outline).mean(axis=0)
    off = float(np.hypot(r - rc, c - cc)) * top.pixel_size
    bound = float(np.sin(active().UPRIGHT_TILT)) * point.pos[2] * lo
    if off <= bound:
        return None
    return Reason("tilted", f"{x}'s {point.name} lies {100 * off:.1f} cm off the centre of its base from the "
                  f"top, where standing within {active().UPRIGHT_TILT} rad of upright it lies at most "
                  f"{100 * bound:.1f} cm off: it tilts")


def _on_table(obs: Observation, a: str) -> tuple[bool, str]:
    ok, why = _released(obs, a)
    if not ok:
        return ok, why
    top = obs.after.get(TOP)
    if top is None:
        return False, Reason("missing_view", "the top view is needed")
    ma = _mask(obs, top, a)
    if not ma.any():
        return False, Reason("not_visible", f"{a} is not visible from the top")
    for i, other in enumerate(obs.labels):
        if other == a:
            continue
        mo = top.segmentation == i
        if mo.sum() > ma.sum() and (ma & hull(mo)).sum() > active().MIN_OVERLAP * ma.sum():
            return False, Reason("on_other_object", f"{a} lies over {other}, not on the table")
    high = _not_down(obs, top, a, 0.0, 0.0, "the table", (a,))  # heights are above the table
    if high is not None:
        return False, high
    return True, "on the table"


def _side(obs: Observation, a: str, b: str, left: bool) -> tuple[bool, str]:
    top = obs.after.get(TOP)
    if top is None:
        return False, Reason("missing_view", "the top view is needed")
    ca, cb = np.nonzero(_mask(obs, top, a))[1], np.nonzero(_mask(obs, top, b))[1]
    if not len(ca) or not len(cb):
        return False, Reason("not_visible", "both objects must be visible from the top")
    d = float(cb.mean() - ca.mean()) if left else float(ca.mean() - cb.mean())
    if d < active().COL_MARGIN:
        return False, Reason("wrong_side", f"column difference {d:.0f} px")
    return True, f"column difference {d:.0f} px"


def _near(obs: Observation, a: str, b: str) -> tuple[bool, str]:
    top = obs.after.get(TOP)
    if top is None or top.pixel_size is None:
        return False, Reason("missing_view", "the orthographic top view is needed")
    pa, pb = np.nonzero(_mask(obs, top, a)), np.nonzero(_mask(obs, top, b))
    if not len(pa[0]) or not len(pb[0]):
        return False, Reason("not_visible", "both objects must be visible from the top")
    rows = float(np.mean(pa[0]) - np.mean(pb[0]))
    cols = float(np.mean(pa[1]) - np.mean(pb[1]))
    d = float(np.hypot(rows, cols)) * top.pixel_size
    if d > active().NEAR:
        return False, Reason("too_far", f"{d * 100:.0f} cm apart from the top")
    return True, f"{d * 100:.0f} cm apart from the top"


def _lifted(obs: Observation, a: str) -> tuple[bool, str]:
    fb, fa, top = obs.before.get(FRONT), obs.after.get(FRONT), obs.after.get(TOP)
    if fb is None or fa is None or top is None:
        return False, Reason("missing_view", "the front views before and after and the top view are needed")
    rb, ra = rows_of(_mask(obs, fb, a)), rows_of(_mask(obs, fa, a))
    if rb is None or ra is None:
        return False, Reason("not_visible", f"{a} is not visible from the front")
    rise = rb[1] - ra[1]
    if rise < active().LIFT_ROWS:
        return False, Reason("too_low", f"{a}'s bottom rose by {rise} px in the front view")
    ma = _mask(obs, top, a)
    for i, other in enumerate(obs.labels):
        mo = top.segmentation == i
        if other != a and mo.sum() > ma.sum() and (ma & hull(mo)).sum() > active().MIN_OVERLAP * ma.sum():
            return False, Reason("on_other_object", f"{a} rests on {other}")
    return True, f"rose by {rise} px"


def _facing(obs: Observation, a: str) -> tuple[bool, str]:
    """``a``'s functional face (a board's printed code, a fan's grille) points at the robot's base.

    The top view gives the face's axis up to its sign: ``a``'s tall part (its pixels at least half
    its height up: a board's plate, a fan's head) is a flat thing, elongated at least
    :data:`FACE_ELONGATION` along itself, whose short axis is the face's normal; that axis must
    point at the robot's base (the view's calibration) within the oracle's :data:`FACE_TOL`. The
    front view gives the sign: its camera looks at the table from the side opposite the robot, so
    an object facing the robot shows it its plain back, and the face's printed detail shows as a
    contrast the back does not have (luminance P90/P10 over the upper part of ``a``'s front-view
    outline above :data:`FACE_CONTRAST`: the face turned away from the robot).
    """
    top, front = obs.after.get(TOP), obs.after.get(FRONT)
    if top is None or front is None or top.robot_base is None:
        return False, Reason("missing_view", "the calibrated top view and the front view are needed")
    heights, mask = _heights(top), _mask(obs, top, a)
    if heights is None or not mask.any():
        return False, Reason("not_visible", f"{a} is not visible from the top (or the top view has no depth)")
    tall = mask & (heights > 0.5 * _highest(heights, mask))
    rows, cols = np.nonzero(tall)
    if len(rows) < 3:
        return False, Reason("not_visible", f"{a}'s upper part does not show from the top")
    spread, axes = np.linalg.eigh(np.cov(np.vstack([rows, cols])))
    if spread[1] < active().FACE_ELONGATION ** 2 * max(float(spread[0]), 1e-9):
        return False, Reason("cannot_tell",
                             f"{a}'s upper part is not flat enough from the top to tell which way it faces")
    to_robot = np.array(top.robot_base) - [rows.mean(), cols.mean()]
    off = float(np.arccos(min(1.0, abs(float(axes[:, 0] @ to_robot)) / float(np.linalg.norm(to_robot)))))
    if off > active().FACE_TOL:
        return False, Reason("turned_away", f"{a}'s face is turned {np.degrees(off):.0f} degrees from the "
                             "robot (from the top)")
    seen = _mask(obs, front, a)
    front_rows = rows_of(seen)
    if front_rows is None:
        return False, Reason("not_visible", f"{a} is hidden from the front: which of its sides faces the "
                             "robot cannot be seen")
    upper = seen.copy()
    upper[front_rows[0] + int(0.6 * (front_rows[1] - front_rows[0])):] = False
    if upper.sum() < active().FACE_MIN_PX:
        return False, Reason("not_visible", f"too little of {a} shows from the front to tell which of its "
                             "sides faces the robot")
    p10, p90 = np.percentile(front.rgb[upper].astype(float).mean(axis=1), [10, 90])
    contrast = float(p90 / max(p10, 1.0))
    if contrast > active().FACE_CONTRAST:
        return False, Reason("facing_away", f"{a} shows its face to the front camera (contrast "
                             f"x{contrast:.1f}): it faces away from the robot")
    return True, f"faces the robot within {np.degrees(off):.0f} degrees, its plain back to the front camera"


def _hanging(obs: Observation, a: str, b: str) -> tuple[bool, str]:
    """``a`` hangs from ``b``: from the top view, ``a``'s highest point stands more than
    :data:`HANG_CLEAR` above its longest side at its type's largest scale (higher than ``a`` reaches
    resting on the table, any way up, or on ``b``'s base), and its outline touches ``b``'s (what holds
    it up is ``b``: a mug's handle lies over the rack's peg)."""
    top = obs.after.get(TOP)
    heights = _heights(top) if top is not None else None
    reach = _max_height(obs, a, any_way_up=True)
    if top is None or heights is None or reach is None:
        return False, Reason("missing_view", "the top view's heights and the object's type are needed")
    ma, mb = _mask(obs, top, a), _mask(obs, top, b)
    if not ma.any() or not mb.any():
        return False, Reason("not_visible", f"{a} or {b} is not visible from the top")
    high = _highest(heights, ma)
    if high < reach + active().HANG_CLEAR:
        return False, Reason("too_low", f"{a}'s top is {100 * high:.1f} cm above the table, no higher than "
                             f"it reaches resting any way up ({100 * reach:.1f} cm): it does not hang")
    if not touch(ma, mb):
        return False, Reason("no_contact", f"{a} does not touch {b} from the top: it does not hang from it")
    return True, f"{a}'s top is {100 * high:.1f} cm above the table, touching {b}"
