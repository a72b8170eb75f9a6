"""The offline image critic: judges a subtask from rendered images and segmentation masks only.

It never reads simulator state. Each predicate of the subtask is checked in image space:

- ``on(a, b)`` / ``inside(a, b)``: in the top view (orthographic) most of ``a``'s pixels lie in
  the convex hull of ``b``'s (or, when ``a`` is the larger, ``b``'s in ``a``'s); in the front view
  ``a`` rests on ``b``: its lowest pixel row lies within ``b``'s rows (for ``inside``, no lower than
  ``b``'s bottom).
- ``released(a)``: after the retreat, the robot does not touch ``a`` in both views (a projection
  overlap in one view is not contact).
- ``pressed(x)``: in the views at the subtask's deepest moment the robot touches ``x`` (front view)
  and covers it (top view), and afterwards ``x`` is still where it was and upright.
- ``upright(x)``: ``x``'s top-view area and front-view height are close to what they were before.
- ``on_table(a)``: released and not over another object in the top view.
- ``left_of`` / ``right_of``: column order in the top view (+y, the robot's left, is image left).
- ``near(a, b)``: the centroids of the two masks in the top view are within the oracle's 10 cm,
  measured with the orthographic view's pixel size.
- ``lifted(a)``: in the front view ``a``'s lowest row rose by at least :data:`LIFT_ROWS` pixels
  since before the subtask, and it is not over another object's top-view hull (it hangs in the air).

Every predicate of :mod:`vcage.vocabulary` has a check in ``IMAGE_CHECKS``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import shapely
from shapely.geometry import MultiPoint

from vcage.critics.base import CRITICS, Critic, CriticConfig, Observation, Verdict, View
from vcage.registry import Registry

ROBOT = -2
TOP, FRONT = "top", "front"
MIN_OVERLAP = 0.6  # share of the smaller region's pixels that must overlap the other's hull
ROW_TOL = 3  # pixels of slack for row comparisons in the front view
TOUCH = 2  # pixels: masks closer than this touch
AREA_RATIO = (0.6, 1.6)  # top-view area after / before for an object that stayed upright
HEIGHT_RATIO = 0.7  # front-view height after / before for an object that stayed upright
COL_MARGIN = 2  # pixels of column separation for left_of / right_of
DEPTH_TOL = 0.02  # metres: adjacent pixels this close in depth are in contact
NEAR = 0.1  # metres between the centroids for ``near`` (the oracle's distance)
LIFT_ROWS = 8  # front-view pixel rows (of 240) an object's bottom must rise to count as lifted


class ImageCritic(Critic):
    name = "image"

    def judge(self, obs: Observation) -> Verdict:
        checks: dict[str, bool] = {}
        reasons: list[str] = []
        for pred in obs.subtask.predicates:
            ok, why = IMAGE_CHECKS.get(pred.name)(obs, *pred.args)
            checks[str(pred)] = ok
            if not ok:
                reasons.append(f"{pred}: {why}")
        accept = not reasons
        reason = "; ".join(reasons) if reasons else "all image checks pass"
        return Verdict(accept, reason, {"checks": checks})


# -- masks ----------------------------------------------------------------------------------------

def _mask(obs: Observation, view: View, name: str) -> np.ndarray:
    return view.segmentation == obs.labels.index(name)


def _hull(mask: np.ndarray) -> np.ndarray:
    """The filled convex hull of a mask's pixels."""
    rows, cols = np.nonzero(mask)
    if len(rows) < 3:
        return mask.copy()
    hull = MultiPoint(np.column_stack([cols, rows]).astype(float)).convex_hull.buffer(0.5)
    r0, r1, c0, c1 = rows.min(), rows.max() + 1, cols.min(), cols.max() + 1
    cc, rr = np.meshgrid(np.arange(c0, c1), np.arange(r0, r1))
    out = np.zeros_like(mask)
    out[r0:r1, c0:c1] = shapely.contains_xy(hull, cc.astype(float), rr.astype(float))
    return out | mask


def _dilate(mask: np.ndarray, px: int) -> np.ndarray:
    out = mask.copy()
    for _ in range(px):
        grown = out.copy()
        grown[1:] |= out[:-1]
        grown[:-1] |= out[1:]
        grown[:, 1:] |= out[:, :-1]
        grown[:, :-1] |= out[:, 1:]
        out = grown
    return out


def _touch(a: np.ndarray, b: np.ndarray, depth: np.ndarray | None = None) -> bool:
    """Masks ``a`` and ``b`` are adjacent; with depth, also at about the same distance (a real
    contact, not one object seen in front of the other)."""
    near = _dilate(a, TOUCH) & b
    if depth is None or not near.any():
        return bool(near.any())
    grown_b = _dilate(b, TOUCH) & a
    da, db = depth[grown_b], depth[near]
    return bool(np.min(np.abs(da[:, None] - db[None, :])) < DEPTH_TOL) if da.size and db.size else False


def _rows(mask: np.ndarray) -> tuple[int, int] | None:
    rows = np.nonzero(mask.any(axis=1))[0]
    return (int(rows[0]), int(rows[-1])) if len(rows) else None


# -- predicate checks: (observation, *objects) -> (ok, reason) -----------------------------------

def _rests_on(obs: Observation, a: str, b: str, inside: bool) -> tuple[bool, str]:
    top = obs.after.get(TOP)
    front = obs.after.get(FRONT)
    if top is None or front is None:
        return False, "the top and front views are needed"
    ma, mb = _mask(obs, top, a), _mask(obs, top, b)
    before = obs.before.get(TOP)
    if before is not None:  # ``a`` now hides part of ``b``: take ``b``'s outline from before too
        mb = mb | _mask(obs, before, b)
    if not ma.any():
        return False, f"{a} is not visible from the top"
    if not mb.any():
        return False, f"{b} is not visible from the top"
    small, big = (ma, mb) if ma.sum() <= mb.sum() else (mb, ma)
    overlap = float((small & _hull(big)).sum() / small.sum())
    if overlap < MIN_OVERLAP:
        return False, f"only {overlap:.0%} of {a} overlaps {b} from the top"
    fa, fb = _rows(_mask(obs, front, a)), _rows(_mask(obs, front, b) | _mask(obs, front, a))
    if fa is not None and fb is not None:
        a_bottom = fa[1]
        if a_bottom < fb[0] - ROW_TOL and not inside:
            return False, f"{a} floats above {b} in the front view"
        if a_bottom > fb[1] + ROW_TOL:
            return False, f"{a} is below {b} in the front view"
    return True, f"{overlap:.0%} overlap from the top"


def _on(obs: Observation, a: str, b: str) -> tuple[bool, str]:
    return _rests_on(obs, a, b, inside=False)


def _inside(obs: Observation, a: str, b: str) -> tuple[bool, str]:
    return _rests_on(obs, a, b, inside=True)


def _released(obs: Observation, a: str) -> tuple[bool, str]:
    """A held object touches the hand in every view; a projection overlap in one is not contact."""
    touching = [cam for cam, view in obs.after.items()
                if _touch(view.segmentation == ROBOT, _mask(obs, view, a), view.depth)]
    if touching and len(touching) == len(obs.after):
        return False, f"the robot still touches {a} in the {' and '.join(touching)} views"
    return True, "the robot is clear of it"


def _pressed(obs: Observation, x: str) -> tuple[bool, str]:
    front, top = obs.during.get(FRONT), obs.during.get(TOP)
    if front is None or top is None:
        return False, "no view of the press"
    mx_front = _mask(obs, front, x)
    if not _touch(front.segmentation == ROBOT, mx_front, front.depth):
        return False, f"the hand never touched {x}"
    mx_top = _mask(obs, top, x)
    before = obs.before.get(TOP)
    if before is not None:  # the hand hides ``x`` from the top: use its outline from before
        mx_top = mx_top | _mask(obs, before, x)
    hull = _hull(mx_top) if mx_top.any() else mx_top
    if not np.any(_dilate(top.segmentation == ROBOT, TOUCH) & hull):
        return False, f"the hand was not over {x}"
    return _stayed(obs, x)


def _stayed(obs: Observation, x: str) -> tuple[bool, str]:
    before, after = obs.before.get(TOP), obs.after.get(TOP)
    if before is None or after is None:
        return False, "the top views before and after are needed"
    mb, ma = _mask(obs, before, x), _mask(obs, after, x)
    if not ma.any():
        return False, f"{x} is not visible from the top afterwards"
    iou = float((mb & ma).sum() / max(1, (mb | ma).sum()))
    if iou < 0.5:
        return False, f"{x} moved (top-view overlap with before {iou:.0%})"
    return _upright(obs, x)


def _upright(obs: Observation, x: str) -> tuple[bool, str]:
    before, after = obs.before.get(TOP), obs.after.get(TOP)
    fb, fa = obs.before.get(FRONT), obs.after.get(FRONT)
    if before is None or after is None or fb is None or fa is None:
        return False, "the top and front views before and after are needed"
    mb, ma = _mask(obs, before, x), _mask(obs, after, x)
    occluded = any(_touch(v.segmentation == ROBOT, m) for v, m in ((before, mb), (after, ma)))
    area_b, area_a = mb.sum(), ma.sum()
    if area_b and not occluded and not AREA_RATIO[0] <= area_a / area_b <= AREA_RATIO[1]:
        return False, f"{x}'s top-view area changed by x{area_a / area_b:.2f} (tipped over?)"
    rb, ra = _rows(_mask(obs, fb, x)), _rows(_mask(obs, fa, x))
    if rb and ra and (ra[1] - ra[0] + 1) < HEIGHT_RATIO * (rb[1] - rb[0] + 1):
        return False, f"{x} looks lower in the front view than before (tipped over?)"
    return True, "upright"


def _on_table(obs: Observation, a: str) -> tuple[bool, str]:
    ok, why = _released(obs, a)
    if not ok:
        return ok, why
    top = obs.after.get(TOP)
    if top is None:
        return False, "the top view is needed"
    ma = _mask(obs, top, a)
    if not ma.any():
        return False, f"{a} is not visible from the top"
    for i, other in enumerate(obs.labels):
        if other == a:
            continue
        mo = top.segmentation == i
        if mo.sum() > ma.sum() and (ma & _hull(mo)).sum() > MIN_OVERLAP * ma.sum():
            return False, f"{a} lies over {other}, not on the table"
    return True, "on the table"


def _side(obs: Observation, a: str, b: str, left: bool) -> tuple[bool, str]:
    top = obs.after.get(TOP)
    if top is None:
        return False, "the top view is needed"
    ca, cb = np.nonzero(_mask(obs, top, a))[1], np.nonzero(_mask(obs, top, b))[1]
    if not len(ca) or not len(cb):
        return False, "both objects must be visible from the top"
    d = float(cb.mean() - ca.mean()) if left else float(ca.mean() - cb.mean())
    return d >= COL_MARGIN, f"column difference {d:.0f} px"


def _near(obs: Observation, a: str, b: str) -> tuple[bool, str]:
    top = obs.after.get(TOP)
    if top is None or top.pixel_size is None:
        return False, "the orthographic top view is needed"
    pa, pb = np.nonzero(_mask(obs, top, a)), np.nonzero(_mask(obs, top, b))
    if not len(pa[0]) or not len(pb[0]):
        return False, "both objects must be visible from the top"
    rows = float(np.mean(pa[0]) - np.mean(pb[0]))
    cols = float(np.mean(pa[1]) - np.mean(pb[1]))
    d = float(np.hypot(rows, cols)) * top.pixel_size
    return d <= NEAR, f"{d * 100:.0f} cm apart from the top"


def _lifted(obs: Observation, a: str) -> tuple[bool, str]:
    fb, fa, top = obs.before.get(FRONT), obs.after.get(FRONT), obs.after.get(TOP)
    if fb is None or fa is None or top is None:
        return False, "the front views before and after and the top view are needed"
    rb, ra = _rows(_mask(obs, fb, a)), _rows(_mask(obs, fa, a))
    if rb is None or ra is None:
        return False, f"{a} is not visible from the front"
    rise = rb[1] - ra[1]
    if rise < LIFT_ROWS:
        return False, f"{a}'s bottom rose by {rise} px in the front view"
    ma = _mask(obs, top, a)
    for i, other in enumerate(obs.labels):
        mo = top.segmentation == i
        if other != a and mo.sum() > ma.sum() and (ma & _hull(mo)).sum() > MIN_OVERLAP * ma.sum():
            return False, f"{a} rests on {other}"
    return True, f"rose by {rise} px"


def _stacked(obs: Observation, *objs: str) -> tuple[bool, str]:
    for lower, upper in zip(objs, objs[1:], strict=False):
        ok, why = _on(obs, upper, lower)
        if not ok:
            return ok, why
    return True, "stacked"


ImageCheck = Callable[..., tuple[bool, str]]  # (observation, *objects) -> (holds, why)
IMAGE_CHECKS: Registry[ImageCheck] = Registry("image check")
_checks: dict[str, ImageCheck] = {
    "on": _on, "inside": _inside, "released": _released, "pressed": _pressed, "upright": _upright,
    "on_table": _on_table, "near": _near, "lifted": _lifted, "stacked": _stacked,
    "left_of": lambda obs, a, b: _side(obs, a, b, True),
    "right_of": lambda obs, a, b: _side(obs, a, b, False),
}
for _name, _check in _checks.items():
    IMAGE_CHECKS.add(_name, _check)


@CRITICS.register("image")
def _image(config: CriticConfig) -> Critic:
    return ImageCritic()
