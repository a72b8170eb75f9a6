"""Stability checks in real physics: interpenetration at t=0, motion while settling, falls."""

from __future__ import annotations

import numpy as np

from vcage.scene.compose import compose
from vcage.scene.layout import Distractors, LayoutSpec
from vcage.scene.placement import place
from vcage.scene.spec import ObjectSpec, SceneSpec
from vcage.scene.stability import StabilityConfig, check_stability, fused
from vcage.skills.reachability import reach_map


def _check(scene: SceneSpec):
    return check_stability(compose(scene).make_world())


def test_context_aware_scene_is_valid():
    scene = place(LayoutSpec(distractors=Distractors(10)), np.random.default_rng(0),
                  reach=reach_map()).scene
    report = _check(scene)
    assert report.ok, report.reason()
    assert report.reason() == "stable"


def test_overlapping_objects_are_reported_by_name():
    scene = SceneSpec(objects=(ObjectSpec("a", "block", (0.5, 0.0)), ObjectSpec("b", "block", (0.52, 0.0))))
    report = _check(scene)
    assert report.interpenetrating and not report.ok
    assert {report.penetrations[0][0], report.penetrations[0][1]} == {"a", "b"}
    assert "interpenetrating" in report.reason() and "mm" in report.reason()


def test_object_over_the_edge_falls_off():
    scene = SceneSpec(objects=(ObjectSpec("can", "can", (0.955, 0.3)),))
    report = _check(scene)
    assert report.fell == ("can",)
    assert not report.interpenetrating and not report.stable


def test_naive_placement_interpenetrates_in_clutter():
    reports = [_check(place(LayoutSpec(distractors=Distractors(20)), np.random.default_rng(s),
                            method="naive").scene) for s in range(2)]
    assert any(r.interpenetrating for r in reports)


def test_objects_on_and_in_supports_rest_stably():
    from vcage.scene.layout import LayoutObject as L
    from vcage.scene.layout import Support

    objs = (L("basket", "basket"), L("bread", "bread", support=Support("basket")),
            L("tray", "tray"), L("sponge", "sponge", support=Support("tray")),
            L("apple", "apple", support=Support("tray")),
            L("b1", "block"), L("b2", "block", support=Support("b1")),
            L("b3", "block", support=Support("b2")),
            L("pad", "mouse_pad"), L("mouse", "mouse", support=Support("pad")))
    for seed in range(2):
        scene = place(LayoutSpec(objects=objs, distractors=Distractors(4)),
                      np.random.default_rng(seed), reach=reach_map()).scene
        report = _check(scene)
        assert report.ok, report.reason()


def test_fused_names_the_objects_placed_into_each_other_not_resting_or_unnamed_ones():
    """Two named blocks placed into each other are fused; one resting on the other after settling is
    not (a contact sinks a fraction of a millimetre); two other objects fused together are not
    named: only pairs with one of ``names`` count."""
    bound = StabilityConfig().penetration

    def pairs(*objects: ObjectSpec, settle: float = 0.0) -> tuple[tuple[str, str, float], ...]:
        world = compose(SceneSpec(objects=objects)).make_world()
        world.settle(settle)
        world.forward()
        return fused(world, {"base", "middle"}, bound)

    placed = pairs(ObjectSpec("base", "block", (0.5, 0.0)), ObjectSpec("middle", "block", (0.52, 0.0)))
    assert [p[:2] for p in placed] == [("base", "middle")] and placed[0][2] > bound
    stacked = (ObjectSpec("base", "block", (0.5, 0.0)), ObjectSpec("middle", "block", (0.5, 0.0), z=0.8))
    assert pairs(*stacked, settle=0.5) == ()
    assert pairs(ObjectSpec("base", "block", (0.5, 0.2)), ObjectSpec("c0", "block", (0.5, 0.0)),
                 ObjectSpec("c1", "block", (0.52, 0.0))) == ()
