"""The oracle covers every predicate a plan may name; the image critic every one it can see."""

from __future__ import annotations

from vcage.critics.image import CHECKS
from vcage.critics.oracle import EVENT_PREDICATES, STATE_PREDICATES
from vcage.planning.schema import PREDICATES


def test_every_plan_predicate_has_a_ground_truth() -> None:
    assert set(PREDICATES) == set(STATE_PREDICATES) | set(EVENT_PREDICATES)


def test_image_critic_checks_all_but_the_invisible_ones() -> None:
    assert set(PREDICATES) - set(CHECKS) == {"near", "lifted"}
