"""Refine: no interpenetration and every relation satisfied, or a typed rejection; then settling."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vcage.assets.catalog import CATALOG
from vcage.synthesis.costs import Problem
from vcage.synthesis.describe import describe
from vcage.synthesis.description import parse_description
from vcage.synthesis.errors import RefineRejected, SettleRejected
from vcage.synthesis.footprints import penetration
from vcage.synthesis.refine import RefineConfig, refine
from vcage.synthesis.settle import scene_spec, settle


def test_refine_separates_overlaps_and_satisfies_the_relations() -> None:
    desc, _ = describe("organize the breakfast table")
    problem = Problem.build(desc, reach=(0.0, 0.0, 0.3, 0.8))
    piled = {o.name: (0.5 + 0.01 * i, 0.01 * i, 0.3 * i) for i, o in enumerate(desc.objects)}  # all overlap
    result = refine(problem, piled, rng=np.random.default_rng(0))
    poses = np.array([result.poses[n] for n in problem.names])
    assert penetration(poses, problem.half, problem.pairs).max() < 0
    assert result.violations["relations"] <= RefineConfig().tolerance
    instance = settle(scene_spec(desc, result.poses))
    assert instance.valid
    bread, basket = instance.world.object_pos("bread"), instance.world.object_pos("basket")
    assert np.hypot(*(bread[:2] - basket[:2])) < 0.06 and bread[2] > basket[2]


def test_an_unsatisfiable_arrangement_is_rejected_after_its_budget() -> None:
    desc = parse_description({
        "prompt": "x", "text": "impossible",
        "objects": [{"name": "a", "type": "apple"}, {"name": "b", "type": "cup"}],
        "relations": [{"kind": "near", "a": "a", "b": "b", "distance": 0.0},
                      {"kind": "left_of", "a": "a", "b": "b", "distance": 0.4}]})
    problem = Problem.build(desc)
    with pytest.raises(RefineRejected, match="after 2 starts"):
        refine(problem, {"a": (0.5, 0.0, 0.0), "b": (0.5, 0.2, 0.0)}, RefineConfig(starts=2, iterations=150))


def test_refine_pushes_apart_unrelated_objects_that_overlap() -> None:
    desc = parse_description({"prompt": "x", "text": "three free objects",
                              "objects": [{"name": "a", "type": "book"}, {"name": "b", "type": "tray"},
                                          {"name": "c", "type": "plate"}]})
    problem = Problem.build(desc)
    result = refine(problem, {"a": (0.5, 0.0, 0.0), "b": (0.51, 0.01, 0.5), "c": (0.49, -0.01, 1.0)})
    poses = np.array([result.poses[n] for n in problem.names])
    assert penetration(poses, problem.half, problem.pairs).max() < -problem.margin / 2 + 1e-3


def test_an_object_on_a_slanted_support_is_dropped_onto_it_and_rests() -> None:
    """A phone cannot start level on the slanted back of its stand: it is dropped onto it instead."""
    desc = parse_description({"prompt": "p", "text": "a phone on its stand",
                              "objects": [{"name": "phone", "type": "phone"},
                                          {"name": "stand", "type": "phone_stand"}],
                              "relations": [{"kind": "on", "a": "phone", "b": "stand"}]})
    slot = CATALOG.get("phone_stand").placements[0].pos
    spec = scene_spec(desc, {"stand": (0.6, 0.0, 0.0), "phone": (0.6 + slot[0], 0.0, math.pi / 2)})
    with pytest.raises(SettleRejected, match="interpenetrating"):
        settle(spec, 0.5)  # as given: the level phone cuts into the slanted back
    inst = settle(spec, 0.5, desc)
    assert inst.valid and inst.world.object_pos("phone")[2] > inst.world.table_top() + 0.02
    tilt = math.degrees(math.acos(float(inst.world.object_mat("phone")[2, 2])))
    assert 5 < tilt < 45  # it leans on the slanted back


def test_relations_held_are_read_on_the_settled_poses() -> None:
    from vcage.synthesis.relations_check import relations_held

    desc = parse_description({"prompt": "p", "text": "a cup left of a plate with an apple",
                              "objects": [{"name": "cup", "type": "cup"}, {"name": "plate", "type": "plate"},
                                          {"name": "apple", "type": "apple"}],
                              "relations": [{"kind": "left_of", "a": "cup", "b": "plate"},
                                            {"kind": "on", "a": "apple", "b": "plate"}]})
    good = {"cup": (0.5, 0.25, 0.0), "plate": (0.5, 0.0, 0.0), "apple": (0.5, 0.005, 0.0)}
    assert [h.held for h in relations_held(desc, good)] == [True, True]
    bad = {"cup": (0.5, -0.25, 0.0), "plate": (0.5, 0.0, 0.0), "apple": (0.7, 0.0, 0.0)}
    held = relations_held(desc, bad)
    assert [h.relation for h in held] == ["left_of(cup, plate)", "on(apple, plate)"]
    assert [h.held for h in held] == [False, False] and held[0].violation > 0.3
    assert relations_held(desc, bad, rests_on={"apple": True})[1].held  # physics says it rests there


def test_a_lost_host_is_anchored_under_what_it_holds() -> None:
    from vcage.synthesis.driver import anchors
    from vcage.synthesis.matching import Match, MatchReport

    desc = parse_description({"prompt": "p", "text": "a cup on a coaster",
                              "objects": [{"name": "cup", "type": "cup"},
                                          {"name": "coaster", "type": "coaster"}],
                              "relations": [{"kind": "on", "a": "cup", "b": "coaster"}]})
    found = Match("cup", True, (0.5, 0.1), 0.3, (1.0, 1.0), 1.0, 0.9)
    lost = Match("coaster", False, (0.3, -0.2), 0.7, (math.nan, math.nan), math.inf, 0.0)
    report = MatchReport({"cup": found, "coaster": lost}, [[1, 0, 0], [0, 1, 0]], True, 0.0, np.zeros(1))
    assert anchors(desc, report) == {"cup": (0.5, 0.1, 0.3), "coaster": (0.5, 0.1, 0.3)}
    report.matches["cup"] = Match("cup", False, (0.4, 0.0), 0.3, (1.0, 1.0), 1.0, 0.1)
    assert anchors(desc, report)["coaster"] == (0.3, -0.2, 0.7)  # both lost: where it started
