"""One vocabulary: every predicate has an oracle check and an image check of its arity, and every
plan skill's declared signature is its primitive's."""

from __future__ import annotations

import inspect
from collections.abc import Callable

import pytest

from vcage.critics.image import IMAGE_CHECKS
from vcage.skills.base import SKILLS
from vcage.tasks.predicates import ORACLE_CHECKS
from vcage.vocabulary import PLAN_SKILLS, PREDICATES


def _accepts(fn: Callable[..., object], n: int, leading: int) -> bool:
    """Whether ``fn`` can be called with ``leading`` fixed arguments plus ``n`` object names."""
    try:
        inspect.signature(fn).bind(*([None] * (leading + n)))
    except TypeError:
        return False
    return True


def test_every_predicate_has_an_oracle_and_an_image_check() -> None:
    assert PREDICATES.names() == ORACLE_CHECKS.names() == IMAGE_CHECKS.names()


@pytest.mark.parametrize("name", PREDICATES.names())
def test_checks_take_exactly_the_declared_number_of_objects(name: str) -> None:
    lo, hi = PREDICATES.get(name).arity
    for checks in (ORACLE_CHECKS, IMAGE_CHECKS):  # (world | observation, *objects)
        fn = checks.get(name)
        assert all(_accepts(fn, n, 1) for n in range(lo, hi + 1)), (name, checks.kind)
        variadic = any(p.kind is p.VAR_POSITIONAL for p in inspect.signature(fn).parameters.values())
        if not variadic:
            assert not _accepts(fn, lo - 1, 1) and not _accepts(fn, hi + 1, 1), (name, checks.kind)


@pytest.mark.parametrize("name", PLAN_SKILLS.names())
def test_plan_skill_signature_is_its_primitives(name: str) -> None:
    spec = PLAN_SKILLS.get(name)
    fn = SKILLS.get(name)
    params = [p for p in inspect.signature(fn).parameters.values() if p.name != "s"]
    assert [p.name for p in params] == [p.name for p in spec.params]
    for p, declared in zip(params, spec.params, strict=True):
        assert (p.default is inspect.Parameter.empty) == declared.required, p.name
        if not declared.required:
            assert p.default == declared.default, p.name
    assert (inspect.getdoc(fn) or "").split("\n")[0] == spec.doc


def test_object_arguments_are_the_ones_that_name_objects() -> None:
    spec = PLAN_SKILLS.get("pick_and_place")
    assert spec.object_args({"obj": "mouse", "target": "pad", "placement": "top"}) == ["mouse", "pad"]
    assert spec.object_args({"obj": "mouse", "xy": [0.5, 0.1]}) == ["mouse"]
