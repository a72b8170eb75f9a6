"""Drawers from the top view: how far a drawer is out, what lies in it; ``opened``, ``closed``."""

from __future__ import annotations

from vcage.assets.annotations import Placement
from vcage.critics.base import Observation, Reason
from vcage.critics.image.measure import _heights, _hidden, _highest, _mask, _scale, _type_of
from vcage.critics.image.thresholds import TOP, active
from vcage.critics.masks import (
    dilate,
    rectangle_sides,
)


def _drawer(obs: Observation, x: str) -> tuple[float, float, bool] | Reason:
    """How far ``x``'s drawer is out after the subtask, by the top view, the travel that counts as
    open (both in metres) and whether the robot hides part of ``x``; or why it cannot be told.

    The type's footprint is the object shut, handle included, and its drawer is narrower than the
    body: pulled out, only the side along which it slides grows. So the smallest rectangle around
    the outline is longer than the footprint, both sides together, by how far the drawer is out
    (the size scaled by the object's height over its type's).
    """
    after = obs.after.get(TOP)
    otype = _type_of(obs, x)
    if after is None or otype is None:
        return Reason("missing_view", f"the top view after the subtask and {x}'s type are needed")
    point = otype.drawer_handle(obs.subtask.args.get("point")) or otype.drawer_handle()
    if point is None:
        return Reason("no_drawer", f"{x} ({otype.name}) has no drawer")
    heights, mask = _heights(after), _mask(obs, after, x)
    if heights is None or after.pixel_size is None or mask.sum() < active().MIN_RELIEF_PX:
        return Reason("not_visible", f"{x} is not seen in the top view's heights")
    scale = _scale(otype, heights, mask)
    long, short = rectangle_sides(mask)
    out = (long + short) * after.pixel_size - (otype.size[0] + otype.size[1]) * scale
    return out, point.travel * scale, _hidden(after, mask) > 0


def _in_drawer(obs: Observation, a: str, b: str, place: Placement) -> tuple[bool, str]:
    """``a`` lies in ``b``'s open drawer (``place``, the placement that comes out with it), by the top
    view's heights: the drawer is still open after the subtask; ``a`` lies over what came out of
    ``b`` (its pixels before the subtask below the top of its body), not on its body; its lowest
    point is below the drawer's rim, and its top is as high as resting on the drawer's floor makes it
    at least (lower, it lies on the table in front of the drawer)."""
    before, after = obs.before.get(TOP), obs.after.get(TOP)
    hb = _heights(before) if before is not None else None
    ha = _heights(after) if after is not None else None
    otype = _type_of(obs, b)
    assert otype is not None  # _inside found b's drawer in it
    if before is None or after is None or hb is None or ha is None:
        return False, Reason("missing_view", "the top view's heights before and after are needed")
    mb, ma = _mask(obs, before, b), _mask(obs, after, a)
    if not mb.any() or not ma.any():
        return False, Reason("not_visible", f"{a} or {b} is not seen from the top")
    drawer = _drawer(obs, b)
    if isinstance(drawer, str) or drawer[0] < drawer[1]:
        return False, Reason("drawer_not_open",
                             f"{b}'s drawer is not open after the subtask, so {a} cannot be seen in it")
    top = _highest(hb, mb)
    body = mb & (hb >= top - active().TOP_BAND_BODY)
    share = float((ma & dilate(mb & ~body, 1)).sum() / ma.sum())
    if share < active().IN_DRAWER:
        return False, Reason("not_over_target",
                             f"only {share:.0%} of {a} lies over {b}'s open drawer from the top")
    scale = _scale(otype, hb, mb)
    lift = max(0.0, top - otype.size[2] * scale)  # standing on something, not on the table
    rim, floor = lift + (place.pos[2] + place.wall_height) * scale, lift + place.pos[2] * scale
    low = float(ha[ma].min())
    if low > rim:
        return False, Reason("too_high",
                             f"{a} lies {100 * (low - rim):.1f} cm higher than the rim of {b}'s drawer")
    atype = _type_of(obs, a)
    if atype is not None:
        a_top = _highest(ha, ma)
        least = floor + atype.size[2] * atype.scale_range[0] - active().FLOOR_TOL
        if a_top < least:
            return False, Reason("too_low", f"{a}'s top is {100 * (least - a_top):.1f} cm lower than lying "
                                 f"on the floor of {b}'s drawer makes it: {a} lies beside the drawer")
    return True, f"{share:.0%} of {a} over {b}'s open drawer"


def _opened(obs: Observation, x: str) -> tuple[bool, str]:
    drawer = _drawer(obs, x)
    if isinstance(drawer, str):
        return False, drawer
    out, travel, hidden = drawer
    if out >= travel + active().OPEN_MARGIN:
        return True, "opened"
    why = (f"{x}'s drawer is out about {100 * out:.1f} cm in the top view, less than the "
           f"{100 * (travel + active().OPEN_MARGIN):.0f} cm that count as open")
    return False, Reason("drawer_not_open", why + (" (the robot hides part of it)" if hidden else ""))


def _closed(obs: Observation, x: str) -> tuple[bool, str]:
    drawer = _drawer(obs, x)
    if isinstance(drawer, str):
        return False, drawer
    out, _, hidden = drawer
    if hidden:
        return False, Reason("robot_hides",
                             f"the robot hides part of {x} in the top view: its drawer may stand out")
    if out > active().SHUT_OUT:
        return False, Reason("drawer_not_shut",
                             f"{x}'s drawer is out about {100 * out:.1f} cm in the top view, not shut")
    return True, "closed"
