"""Candidates from the catalog's annotations, and the parent's check of every skill call."""

from __future__ import annotations

import json

import pytest

from vcage.errors import SubtaskError
from vcage.sandbox import Call
from vcage.scene.spec import ObjectSpec, SceneSpec
from vcage.subtasks.calls import check_call
from vcage.subtasks.candidates import candidates
from vcage.subtasks.stats import accepted, pass_at_k, top_k_mean, wilson
from vcage.subtasks.trial import template_calls, trial_seed

SCENE = SceneSpec(objects=(ObjectSpec("cube", "block", (0.45, -0.15)),
                           ObjectSpec("dish", "plate", (0.6, 0.1)),
                           ObjectSpec("pot", "pot", (0.6, -0.25)), ObjectSpec("cup", "cup", (0.4, 0.2)),
                           ObjectSpec("switch", "switch", (0.45, 0.3))))


def test_candidates_pair_graspable_objects_with_surfaces_they_fit_and_press_functional_points() -> None:
    found = {(c.template, tuple(c.args.values())) for c in candidates("s", SCENE)}
    assert found == {
        ("put_on", ("cube", "dish")), ("put_in", ("cube", "pot")), ("put_in", ("cube", "cup")),
        ("put_on", ("cup", "dish")), ("put_in", ("cup", "pot")),  # no pot on the plate: larger than it
        ("press", ("switch", "on")), ("press", ("switch", "off")),
    }
    cube_on_dish = next(c for c in candidates("s", SCENE) if c.args == {"obj": "cube", "target": "dish"})
    assert [str(p) for p in cube_on_dish.predicates] == ["on(cube, dish)", "released(cube)"]
    assert template_calls(cube_on_dish.code) == [Call("pick_and_place", {"obj": "cube", "target": "dish"})]
    assert json.loads(cube_on_dish.code) == [{"skill": "pick_and_place",
                                              "args": {"obj": "cube", "target": "dish"}}]


def test_a_bowl_nests_in_a_larger_bowl_and_same_type_containers_otherwise_do_not() -> None:
    bowls = SceneSpec(objects=(ObjectSpec("small", "bowl", (0.45, -0.15), scale=0.85),
                               ObjectSpec("large", "bowl", (0.6, 0.1)),
                               ObjectSpec("twin", "bowl", (0.6, -0.2)),
                               ObjectSpec("cup_a", "cup", (0.45, 0.2), scale=0.7),
                               ObjectSpec("cup_b", "cup", (0.4, 0.0))))
    nested = {tuple(c.args.values()) for c in candidates("s", bowls) if c.template == "put_in"
              and bowls.object(c.args["obj"]).type == bowls.object(c.args["target"]).type}
    assert nested == {("small", "large"), ("small", "twin")}  # not large in twin: the same size


def test_identity_and_trial_seeds_are_deterministic() -> None:
    a, b = candidates("s", SCENE), candidates("s", SCENE)
    assert [c.id for c in a] == [c.id for c in b] and len({c.id for c in a}) == len(a)
    assert candidates("t", SCENE)[0].id != a[0].id  # another scene, another subtask
    assert trial_seed(a[0].id, 3) == trial_seed(a[0].id, 3) != trial_seed(a[0].id, 4)
    program = a[0].with_program("pick_and_place(obj='cube', target='dish')\n", "m", "h")
    assert program.id != a[0].id and program.source == "llm"


@pytest.mark.parametrize(("call", "message"), [
    (Call("fly", {}), "unknown skill 'fly'"),
    (Call("press", {"obj": "ghost"}), "'ghost' is not an object of the scene"),
    (Call("press", {}), "needs argument(s) ['obj']"),
    (Call("press", {"obj": "switch", "force": 3}), "has no argument(s) ['force']"),
    (Call("press", {"obj": "switch", "point": "middle"}), "unknown switch functional point 'middle'"),
    (Call("press", {"obj": "switch", "depth": float("nan")}), "nan is not a finite number"),
    (Call("press", {"obj": "switch", "depth": 5}), "outside [0, 0.03]"),
    (Call("pick_and_place", {"obj": "cube", "xy": [float("inf"), 0.0]}), "inf is not a finite number"),
    (Call("pick_and_place", {"obj": "cube", "xy": [2.0, 0.0]}), "is off the table"),
    (Call("pick_and_place", {"obj": "cube", "xy": [0.5]}), "expected two numbers"),
    (Call("pick_and_place", {"obj": "cube", "target": "dish", "placement": "rim"}),
     "unknown plate placement"),
    (Call("pick_and_place", {"obj": "cube", "grasp_name": "nope"}), "has no grasp 'nope'"),
    (Call("push", {"obj": "cube", "direction": [0, 0], "distance": 0.1}), "non-zero"),
    (Call("retreat", {"home": "yes"}), "must be true or false"),
])
def test_invalid_calls_are_refused_naming_the_argument(call: Call, message: str) -> None:
    with pytest.raises(SubtaskError) as err:
        check_call(call, SCENE)
    assert message in str(err.value)


def test_valid_calls_become_skill_arguments() -> None:
    ok = check_call(Call("pick_and_place", {"obj": "cube", "xy": [0.5, 0.1], "target": None}), SCENE)
    assert ok.skill == "pick_and_place" and ok.kwargs == {"obj": "cube", "xy": (0.5, 0.1)}


def test_the_acceptance_rule_is_strict_and_the_interval_is_wilson() -> None:
    assert not accepted(5, 10) and accepted(6, 10) and not accepted(0, 0)
    assert wilson(8, 10) == pytest.approx((0.4902, 0.9433), abs=1e-4)
    assert wilson(0, 10)[0] == 0.0 and wilson(10, 10)[1] == 1.0


def test_pass_at_k_is_the_unbiased_estimator() -> None:
    assert pass_at_k(10, 0, 1) == 0.0 and pass_at_k(10, 10, 1) == 1.0
    assert pass_at_k(10, 3, 1) == pytest.approx(0.3)
    assert pass_at_k(10, 3, 5) == pytest.approx(1 - 21 / 252)  # 1 - C(7,5)/C(10,5)
    assert top_k_mean([0.1, 0.9, 0.5, 0.7]) == pytest.approx(0.7)
