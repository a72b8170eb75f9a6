"""Refine: no interpenetration and every relation satisfied, or a typed rejection; then settling."""

from __future__ import annotations

import numpy as np
import pytest

from vcage.synthesis.costs import Problem
from vcage.synthesis.describe import describe
from vcage.synthesis.description import parse_description
from vcage.synthesis.errors import RefineRejected
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
