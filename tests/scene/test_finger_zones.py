"""Finger zones: context-aware placement keeps every footprint out of the ground the open fingers
sweep to grasp a task object, so a neighbour never blocks a grasp."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from vcage.config import Randomization
from vcage.scene.instantiate import SceneConfig
from vcage.scene.layout import Distractors, LayoutObject, LayoutSpec, Region
from vcage.scene.placement import PlacementConfig, place
from vcage.scene.placement.geometry import footprint, grasp_zone
from vcage.sim import robot as R
from vcage.skills.reachability import reach_map
from vcage.tasks.runner import prepare


@pytest.fixture(scope="module")
def reach():
    return reach_map()


# Graspable task objects packed into a small region: without zones they end up side by side.
AREA = Region((0.5, 0.0), (0.1, 0.15))
PACKED = (LayoutObject("mouse", "mouse", region=AREA), LayoutObject("clock", "alarm_clock", region=AREA),
          LayoutObject("bread", "bread", region=AREA))


def _violations(scene, cfg: PlacementConfig) -> list[tuple[str, str]]:
    """Pairs (object, task object) where the object's footprint enters the task object's zone."""
    task = {o.name for o in PACKED}
    out = []
    for a, b in itertools.permutations(scene.objects, 2):
        if b.name not in task:
            continue
        zone = grasp_zone(b.type, b.scale, b.yaw, b.xy, cfg.finger_slack)
        assert zone is not None
        if footprint(a.type, a.scale, a.yaw, a.xy).intersects(zone):
            out.append((a.name, b.name))
    return out


def test_no_footprint_stands_where_fingers_grasp_a_task_object(reach):
    zones, plain = PlacementConfig(), PlacementConfig(finger_zones=False)
    before = 0
    for seed in range(6):
        layout = LayoutSpec(objects=PACKED, distractors=Distractors(4))
        with_zones = place(layout, np.random.default_rng(seed), config=zones, reach=reach).scene
        assert _violations(with_zones, zones) == [], seed
        before += len(_violations(place(layout, np.random.default_rng(seed), config=plain,
                                        reach=reach).scene, zones))
    assert before > 0  # the same layouts without zones do block grasps: the check above can fail


def test_zone_covers_the_footprint_and_both_fingers():
    zone = grasp_zone("mouse", 1.0, 0.0, (0.5, 0.1))
    assert zone is not None and zone.covers(footprint("mouse", 1.0, 0.0, (0.5, 0.1)))
    # the mouse is grasped across its width (y): the zone reaches the open fingers' outer faces
    _, y0, _, y1 = zone.bounds
    assert y1 - 0.1 == pytest.approx(R.FINGER_OUTER) and 0.1 - y0 == pytest.approx(R.FINGER_OUTER)
    turned = grasp_zone("mouse", 1.0, math.pi / 2, (0.5, 0.1))
    assert turned is not None and turned.bounds[2] - 0.5 == pytest.approx(R.FINGER_OUTER)
    assert grasp_zone("mouse_pad", 1.0, 0.0) is None  # nothing grasps a pad


def test_finger_box_constants_match_the_robot_model():
    _, world, _ = prepare("place_mouse_pad", 0, Randomization())
    m, d = world.model, world.data
    tcp = d.site(R.TCP_SITE)
    frame = tcp.xmat.reshape(3, 3)
    across, along = 0.0, 0.0
    for g in range(m.ngeom):
        if m.body(m.geom_bodyid[g]).name not in R.FINGER_BODIES or m.geom_contype[g] == 0:
            continue
        center, half = m.geom_aabb[g][:3], m.geom_aabb[g][3:]  # the geom's bounding box, own frame
        corners = center + half * np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1)
                                            for sz in (-1, 1)])
        points = d.geom_xpos[g] + corners @ d.geom_xmat[g].reshape(3, 3).T
        local = (points - tcp.xpos) @ frame
        across = max(across, float(np.abs(local[:, 0]).max()))
        along = max(along, float(np.abs(local[:, 1]).max()))
    assert [world.joint_value(j) for j in R.FINGER_JOINTS] == pytest.approx([R.GRIPPER_OPEN] * 2, abs=1e-3)
    assert along <= R.FINGER_OUTER and along == pytest.approx(R.FINGER_OUTER, abs=1e-3)
    assert across <= R.FINGER_HALF_WIDTH and across == pytest.approx(R.FINGER_HALF_WIDTH, abs=1e-3)


def test_configs_stored_before_finger_zones_keep_placing_without_them():
    old = {k: v for k, v in PlacementConfig().__dict__.items() if k not in ("finger_zones", "finger_slack")}
    assert PlacementConfig.from_dict(old).finger_zones is False
    assert PlacementConfig.from_dict({"margin": 0.02}).finger_zones is True  # a partial config: defaults
    scene = SceneConfig.from_dict({"clutter": 2, "placement_config": old})
    assert scene.placement_config.finger_zones is False
    assert SceneConfig.from_dict(SceneConfig().to_dict()) == SceneConfig()
