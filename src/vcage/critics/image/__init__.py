"""The offline image critic: judges a subtask from rendered images and segmentation masks only.

It sees what :mod:`vcage.tasks.verifier` renders around the subtask: the orthographic top view
(RGB and the renderer's segmentation masks, with its pixel size in metres) and the perspective front
view (RGB, segmentation and depth), before the subtask, at its deepest moment (where the hand was
lowest in the subtask's own motion, not in what ran after it) and after the retreat. It never reads
simulator state. Each predicate is checked in image space:

- ``on(a, b)`` / ``inside(a, b)``: in the top view most of ``a``'s pixels lie in the convex hull of
  ``b``'s outline (or, when ``a`` is the larger, ``b``'s in ``a``'s; on a cube, whose surface is its
  whole face, only the centre counts) and ``a``'s centre lies over it; ``b``'s outline is its
  visible pixels plus its outline from before, moved to where it is now (``a`` may hide ``b``, and
  both may have moved). In the front view ``a`` rests on ``b``: its lowest pixel row lies within
  ``b``'s rows (for ``inside``, no lower than ``b``'s bottom). With the top view's depth, ``a`` is
  down on ``b``: its lowest point is no higher than its type's height above ``b``'s surface (for
  ``inside``, its rim), and it does not lie over another object that stood higher than that surface
  before the subtask and is still there (clutter on the target; a flat one, such as a phone lying on
  the target, where it lay under most of ``a``'s outline); an object that stood on its base with a
  curved top before and shows a flat one now, or a domed one that barely bends now, lies turned over,
  as does one whose type declares a domed top (a mouse) and whose top is far flatter than that, or
  whose top's plane slopes well beyond the surface under it (not a cube: it rests on any face), and
  one taller than wide whose top is now nearer its height lying on a side than its height standing
  (read before, on the table; where it did not stand there, the bounds its type's scales allow) lies
  on its side, and so does a deep open container (a cup) whose top view, showing most of it, does
  not show its inside (neither asked in a container, where it may lie any way up; the side is asked
  also where ``a`` hides ``b``). Put down, ``a``'s top (an open
  container's: its rim, at its outline) stands no higher than its type's height above that surface
  (on a surface that leans, a stand's ramp, its longest side across tilted with the ramp; in a
  container, where its top view shows it turned or its top slopes as a leaning object's does, its
  longest side above the rim). In a container its underside, its own height (seen on the table
  before) under its top, or under its top's lower end where it leans, lies below the rim (not
  resting on it), and its centre lies in from ``b``'s outline at least as far as ``b``'s region for
  the oracle does and, lying level, at least half ``a``'s smallest side (leaning, its lower end's
  centre lies over the region): a loaf lying across the wall is not in. In a drawer (a placement
  that comes out with a joint) the drawer is still open after the subtask, and ``a`` lies over what
  came out of ``b`` (not on its body), below the drawer's rim, and no lower than lying on the
  drawer's floor makes it.
- ``released(a)``: after the retreat, the robot does not touch ``a`` in every view that shows it
  (a projection overlap in one view is not contact); ``a`` hidden in every view is not released.
- ``pressed(x)``: in the views at the subtask's deepest moment the robot touches ``x`` (front view,
  at the same depth) and covers it (top view; with the top view's depth, at least
  :data:`BUTTON_COVER` of its top, where the button is), and, where the top view has depth and ``x``'s type
  is known, the hand went deep enough: the orthographic top view's depth gives heights above the
  table, the robot's highest point over ``x``'s outline is the top of the wrist, :data:`HAND_TOP`
  above the hand's centre between the fingertips when the hand points down (as it does to press),
  and at a full press that centre is :data:`FINGER_CONTACT` minus the button's travel (a lever's
  stroke), scaled by ``x``'s size, above ``x``'s highest point before. A press that stops short of
  :data:`PRESS_SHARE` of that is refused, and so is one that reads more than :data:`PRESS_ROOM`
  deeper than a full press: ``x`` gave way under the hand (it rocked or fell). Where the hand goes
  down behind an object standing in front of ``x`` (a cup before a bell), or ``x`` does not show in
  the front view at all, the front view cannot show the contact; then the top view's cover and
  depth, both required, decide.
- ``upright(x)``: ``x``'s top-view area (orthographic, so true to size wherever it stands) and the
  spread of its outline are close to what they were before, allowing for what the robot can hide;
  its highest point (the top view's depth; without it, its front-view height) did not drop, and
  stands no higher than its type's height at the largest scale allows unless something stands
  under it (a bell that lay tipped before the subtask too), and, for a round object with its press
  point on its axis (a bell's button), that point (its top) lies over the centre of its outline
  within what a tilt of the oracle's bound allows (a bell left leaning where it stood before).
- ``hanging(a, b)``: from the top view, ``a``'s highest point stands higher than ``a`` reaches
  resting any way up (its longest side, at its type's largest scale) and ``a`` touches ``b``.
- ``facing(x)``: the short axis of ``x``'s tall part from the top (a board's plate, a fan's head)
  points at the robot's base, whose pixel the top view carries (its calibration), and the front
  camera, opposite the robot, sees the plain back rather than the detailed face (its contrast).
- ``on_table(a)``: released, not over another object in the top view, and down on the table by the
  top view's heights (as for ``on``).
- ``left_of`` / ``right_of``: column order in the top view (+y, the robot's left, is image left).
- ``near(a, b)``: the centroids of the two masks in the top view are within the oracle's 10 cm,
  measured with the orthographic view's pixel size.
- ``lifted(a)``: in the front view ``a``'s lowest row rose by at least :data:`LIFT_ROWS` pixels
  since before the subtask, and it is not over another object's top-view hull (it hangs in the air).
- ``opened(x)`` / ``closed(x)``: how far ``x``'s drawer is out, from the top view after the
  subtask: the sides of the smallest rectangle around ``x``'s outline, together, less its type's
  footprint (the object shut; the drawer is narrower than the body, so only the side it slides along
  grows); open from the handle's travel and :data:`OPEN_MARGIN` on, shut under :data:`SHUT_OUT`.
  Where the robot hides part of ``x`` a drawer is not judged shut.

Every predicate of :mod:`vcage.vocabulary` has a check in ``IMAGE_CHECKS``. Without the top view's
depth (or the object's type), a press that touches the button but moves it less than its travel (a
few millimetres, about one pixel of the front view) looks like a press.
"""

from __future__ import annotations

import functools
import hashlib
import json
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from vcage.critics import masks
from vcage.critics.base import CRITICS, THRESHOLDS, Critic, CriticConfig, Observation, Reason, Verdict
from vcage.critics.image import thresholds
from vcage.critics.image.drawers import _closed, _opened
from vcage.critics.image.pose import _facing, _hanging, _lifted, _near, _on_table, _side, _upright
from vcage.critics.image.press import _pressed, _released
from vcage.critics.image.support import _inside, _on, _stacked
from vcage.registry import Registry


def rule_files() -> list[Path]:
    """The files the image critic's verdicts depend on: this package (every check and threshold) and
    the mask operations it uses."""
    return sorted([*Path(__file__).parent.glob("*.py"), Path(masks.__file__)], key=lambda p: p.name)


def rules_digest(files: Sequence[Path] | None = None) -> str:
    """A digest of the image critic's rules (``files``, default :func:`rule_files`): any change to a
    rule or a threshold changes it."""
    digest = hashlib.sha256()
    for path in rule_files() if files is None else files:
        digest.update(path.name.encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()[:12]


class ImageCritic(Critic):
    """``overrides``: thresholds by name (``CriticConfig.thresholds``) in place of their defaults
    (:mod:`~vcage.critics.image.thresholds`); the checks read them while this critic judges."""

    name = "image"

    def __init__(self, overrides: Mapping[str, Any] | None = None) -> None:
        self.thresholds = thresholds.overridden(overrides or {})

    def version(self) -> str:
        """``image@<rules digest>``, followed by ``+<digest>`` of the thresholds that differ from the
        defaults where some do."""
        changed = thresholds.changed(self.thresholds)
        if not changed:
            return f"image@{_DIGEST()}"
        digest = hashlib.sha256(json.dumps(changed, sort_keys=True).encode()).hexdigest()[:12]
        return f"image@{_DIGEST()}+{digest}"

    def rules(self) -> dict[str, Any]:
        return thresholds.values(self.thresholds)

    def judge(self, obs: Observation) -> Verdict:
        """Every predicate's check; a rejection's ``codes`` name each failed predicate with its
        reason's code (``pressed.too_shallow``, see :data:`~vcage.critics.image.reasons.REASON_CODES`),
        in the predicates' order."""
        checks: dict[str, bool] = {}
        reasons: list[str] = []
        codes: list[str] = []
        with thresholds.using(self.thresholds):
            for pred in obs.subtask.predicates:
                ok, why = IMAGE_CHECKS.get(pred.name)(obs, *pred.args)
                checks[str(pred)] = ok
                if not ok:
                    reasons.append(f"{pred}: {why}")
                    codes.append(f"{pred.name}.{why.code if isinstance(why, Reason) else UNSPECIFIED}")
        accept = not reasons
        reason = "; ".join(reasons) if reasons else "all image checks pass"
        return Verdict(accept, reason, {"checks": checks}, tuple(codes))


ImageCheck = Callable[..., tuple[bool, str]]  # (observation, *objects) -> (holds, why: a Reason if not)
UNSPECIFIED = "unspecified"  # the code of a failure whose why is not a Reason: no check returns one
IMAGE_CHECKS: Registry[ImageCheck] = Registry("image check")
_checks: dict[str, ImageCheck] = {
    "on": _on, "inside": _inside, "released": _released, "pressed": _pressed, "upright": _upright,
    "on_table": _on_table, "near": _near, "lifted": _lifted, "stacked": _stacked, "opened": _opened,
    "closed": _closed, "facing": _facing, "hanging": _hanging,
    "left_of": lambda obs, a, b: _side(obs, a, b, True),
    "right_of": lambda obs, a, b: _side(obs, a, b, False),
}
for _name, _check in _checks.items():
    IMAGE_CHECKS.add(_name, _check)


@CRITICS.register("image")
def _image(config: CriticConfig) -> Critic:
    return ImageCritic(config.thresholds)


@THRESHOLDS.register("image")
def _image_thresholds(given: Mapping[str, Any]) -> dict[str, Any]:
    return thresholds.values(thresholds.overridden(given))


_DIGEST = functools.cache(rules_digest)
