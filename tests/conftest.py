"""Shared fixtures: small real scenes (MuJoCo, no mocks)."""

from __future__ import annotations

import pytest

from vcage.scene.compose import compose
from vcage.scene.spec import ObjectSpec, SceneSpec
from vcage.sim.world import World


@pytest.fixture()
def two_blocks() -> SceneSpec:
    return SceneSpec(objects=(ObjectSpec("a", "block", (0.5, -0.1), color="red"),
                              ObjectSpec("b", "block", (0.5, 0.1), color="blue")))


@pytest.fixture()
def world(two_blocks: SceneSpec) -> World:
    return compose(two_blocks).make_world()
