"""Contact from the views: ``released`` (the robot lets go) and ``pressed`` (it touched, covered and
went deep enough)."""

from __future__ import annotations

import numpy as np

from vcage.critics.base import Observation, Reason, View
from vcage.critics.image.measure import _heights, _mask, _peak, _top_band, _touch_depth, _type_of
from vcage.critics.image.thresholds import FRONT, ROBOT, TOP, active
from vcage.critics.masks import (
    TOUCH,
    dilate,
    hull,
    touch,
)


def _released(obs: Observation, a: str) -> tuple[bool, str]:
    """A held object touches the hand in every view; a projection overlap in one is not contact."""
    seen = {cam: view for cam, view in obs.after.items() if _mask(obs, view, a).any()}
    if not seen:  # hidden in every view: inside the hand, or gone; no view shows it let go
        return False, Reason("not_visible", f"{a} is not visible in any view after the subtask")
    touching = [cam for cam, view in seen.items()
                if touch(view.segmentation == ROBOT, _mask(obs, view, a), _touch_depth(view))]
    if touching and len(touching) == len(seen):
        return False, Reason("still_touching",
                             f"the robot still touches {a} in the {' and '.join(touching)} views")
    return True, "the robot is clear of it"


def _pressed(obs: Observation, x: str) -> tuple[bool, str]:
    front, top = obs.during.get(FRONT), obs.during.get(TOP)
    if front is None or top is None:
        return False, Reason("missing_view", "no view of the press")
    mx_front = _mask(obs, front, x)
    hidden = False
    if not touch(front.segmentation == ROBOT, mx_front, front.depth):
        hidden = _contact_hidden(obs, front, x)
        if not hidden:
            return False, Reason("no_contact", f"the hand never touched {x}")
    mx_top = _mask(obs, top, x)
    before = obs.before.get(TOP)
    if before is not None:  # the hand hides ``x`` from the top: use its outline from before
        mx_top = mx_top | _mask(obs, before, x)
    outline = hull(mx_top) if mx_top.any() else mx_top
    if not np.any(dilate(top.segmentation == ROBOT, TOUCH) & outline):
        return False, Reason("not_over_target", f"the hand was not over {x}")
    cover, reading = _button_cover(obs, x), _press_depth(obs, x)
    if hidden and (cover is None or reading is None):
        return False, Reason("cannot_tell", f"an object in front hides where the hand met {x}, and the top "
                             "view cannot measure it")
    if cover is not None and cover < active().BUTTON_COVER:
        return False, Reason("not_covered",
                             f"the hand covered {cover:.0%} of {x}'s top (its button) at its lowest")
    if reading is not None:
        depth, full, share = reading
        if depth < share * full:
            return False, Reason("too_shallow", f"the hand stopped {1000 * (share * full - depth):.1f} mm "
                                 f"short of pressing {x} down its travel")
        if depth > full + active().PRESS_ROOM:
            return False, Reason("too_deep", f"the hand went {1000 * (depth - full):.1f} mm deeper than a "
                                 f"full press of {x}: {x} gave way under it (tipped, slid or fell)")
    return True, "the hand touched and covered it at its lowest"


def _contact_hidden(obs: Observation, front: View, x: str) -> bool:
    """The hand goes down behind another object in the front view, over ``x``'s columns: its lowest
    pixels there border an object nearer the camera than the hand, so whether it met ``x`` cannot be
    seen from the front (a cup standing in front of a bell). Where the hand ends above the table or
    beside ``x`` in plain sight, its contact (or its absence) is visible. Where ``x`` shows in the
    front view neither now nor before (a bell behind a basket), nothing there can tell. Where what
    shows of ``x`` borders an object nearer the camera, ``x`` may reach on behind it: its columns count
    as ``x``'s (a bell showing a sliver beside the pen holder that hides the rest of it)."""
    seg, depth = front.segmentation, front.depth
    mask = _mask(obs, front, x)
    if FRONT in obs.before:  # what the hand or the occluder hides now may have shown before
        mask = mask | _mask(obs, obs.before[FRONT], x)
    if depth is None:
        return False
    if not mask.any():
        return True
    robot = seg == ROBOT
    below, below_depth = seg[1:], depth[1:]
    occluder = (robot[:-1] & (below >= 0) & (below != obs.labels.index(x))
                & (below_depth < depth[:-1] - active().NEARER))
    span, ring = mask.copy(), dilate(mask, TOUCH)
    for label in np.unique(seg[ring & ~mask & (seg >= 0)]):  # objects beside what shows of x, nearer
        other = seg == label
        if np.median(depth[other & ring]) < np.median(depth[mask]) - active().NEARER:
            span |= other
    cols = np.nonzero(span.any(axis=0))[0]  # the columns x spans (its visible parts may be slivers)
    return bool(occluder[:, max(cols[0] - TOUCH, 0):cols[-1] + TOUCH + 1].any())


def _button_cover(obs: Observation, x: str) -> float | None:
    """Share of ``x``'s top (its pixels within :data:`TOP_BAND` of its highest point before the
    subtask, where a button or lever is) that the robot hides from the top view at the subtask's
    lowest moment; None without the top view's depth."""
    before, during = obs.before.get(TOP), obs.during.get(TOP)
    if before is None or during is None:
        return None
    hb = _heights(before)
    if hb is None:
        return None
    mask = _mask(obs, before, x)
    if not mask.any():
        return None
    top = _top_band(hb, mask)
    return float(((during.segmentation == ROBOT) & top).sum() / top.sum())


def _press_depth(obs: Observation, x: str) -> tuple[float, float, float] | None:
    """How far (metres) the hand pressed ``x`` down at its lowest (its fingertips under ``x``'s top
    before), a full press of ``x`` and the share of it (:data:`PRESS_SHARE`) that must be reached;
    None where the views or ``x``'s type cannot tell."""
    before, during = obs.before.get(TOP), obs.during.get(TOP)
    otype = _type_of(obs, x)
    if before is None or during is None or otype is None:
        return None
    point = next((p for p in otype.functional_points if p.joint and p.name == obs.subtask.args.get("point")),
                 next((p for p in otype.functional_points if p.joint), None))
    hb, hd = _heights(before), _heights(during)
    mask = _mask(obs, before, x)
    if point is None or point.kind not in active().PRESS_SHARE or hb is None or hd is None or not mask.any():
        return None
    over = (during.segmentation == ROBOT) & mask
    if not over.any():
        return None
    top = _peak(hb, mask)  # the button (lever) at rest: the object's highest point
    scale = top / point.pos[2]  # the press point at rest is the highest point
    full = (point.travel if point.kind == "button" else point.stroke) * scale
    tcp = float(hd[over].max()) - active().HAND_TOP
    return top - (tcp - active().FINGER_CONTACT), full, active().PRESS_SHARE[point.kind]
