"""The image critic's reason codes: what each code of a failed check's :class:`~vcage.critics.base.Reason`
means. A verdict names them with the predicate (``pressed.too_shallow``); every code a check returns is
here, and every code here is returned by some check (``tests/critics/test_reason_codes.py``)."""

from __future__ import annotations

REASON_CODES: dict[str, str] = {
    "missing_view": "a view the check needs (or its depth or calibration, or an object's type) is missing",
    "not_visible": "an object the check needs does not show, or too little of it, in the views",
    "cannot_tell": "the views cannot settle the check (a contact hidden in front, a shape too unclear)",
    "not_over_target": "the object (for a press, the hand) does not lie over its target",
    "floating": "in the front view the object's bottom lies above its target's top",
    "below_target": "in the front view the object's bottom lies below its target's bottom",
    "not_resting": "in the front view the object does not rest on its target (hidden from the top)",
    "too_high": "the object stands higher than resting on its support (or in a drawer, under its rim) allows",
    "too_tall": "the object's top stands higher than it reaches standing on its base (tipped or propped)",
    "too_low": "the object is lower than the predicate needs (not lifted, not hanging, beside a drawer)",
    "on_other_object": "the object lies over another object instead of down on its support or the table",
    "on_rim": "the object rests on its container's rim (or on something in it), not down in it",
    "across_wall": "the object's centre lies too near its container's outline: across its wall or outside it",
    "lying_on_side": "the object lies on its side instead of standing on its base",
    "turned_over": "the object's top is flat where it stands domed: it lies turned over",
    "tilted": "the object leans: its domed top slopes, or its top lies off the centre of its base",
    "area_changed": "the object's top-view area changed as a tipped object's does",
    "shape_changed": "the object's top-view outline stretched as a tipped object's does",
    "lower_than_before": "the object's top stands lower than before the subtask",
    "still_touching": "the robot still touches the object after letting go",
    "no_contact": "the hand never touched the object, or the object does not touch what should hold it",
    "not_covered": "the hand covered too little of the button at the press's lowest moment",
    "too_shallow": "the hand stopped short of pressing the button down its travel",
    "too_deep": "the hand went deeper than a full press: the object gave way under it",
    "drawer_not_open": "the drawer is not out far enough to count as open",
    "drawer_not_shut": "the drawer is out too far to count as shut",
    "robot_hides": "the robot hides part of the object, so its drawer may stand out",
    "no_drawer": "the object's type has no drawer",
    "wrong_side": "the object is not on the asked side of the other in the top view",
    "too_far": "the objects' centres lie farther apart than near allows",
    "turned_away": "the object's face is turned away from the robot's base in the top view",
    "facing_away": "the front camera, opposite the robot, sees the object's face: it faces away from it",
}
