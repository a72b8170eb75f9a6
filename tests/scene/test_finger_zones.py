"""Finger zones: context-aware placement keeps every footprint out of the ground the open fingers
sweep to grasp a task object, so a neighbour never blocks a grasp."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
import shapely

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
        assert zone
        if any(footprint(a.type, a.scale, a.yaw, a.xy).intersects(piece) for piece in zone):
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


def test_zones_are_the_open_fingers_of_each_grasp():
    # the mouse is grasped across its width (y), from either side: one box, to the fingers' outer faces
    (zone,) = grasp_zone("mouse", 1.0, 0.0, (0.5, 0.1))
    x0, y0, x1, y1 = zone.bounds
    assert y1 - 0.1 == pytest.approx(R.FINGER_OUTER) and 0.1 - y0 == pytest.approx(R.FINGER_OUTER)
    assert x1 - 0.5 == pytest.approx(R.FINGER_HALF_WIDTH) and 0.5 - x0 == pytest.approx(R.FINGER_HALF_WIDTH)
    (turned,) = grasp_zone("mouse", 1.0, math.pi / 2, (0.5, 0.1))
    assert turned.bounds[2] - 0.5 == pytest.approx(R.FINGER_OUTER)
    assert len(grasp_zone("block", 1.0, 0.0)) == 2  # two grasps a quarter turn apart
    assert grasp_zone("mouse_pad", 1.0, 0.0) == ()  # nothing grasps a pad


def test_only_objects_the_plan_grasps_keep_zones(reach):
    cfg = PlacementConfig()
    target = LayoutObject("bowl", "bowl", region=AREA, grasped=False)  # a target: rim grasps unused
    mouse = LayoutObject("mouse", "mouse", region=AREA)
    hits = 0
    for seed in range(6):
        scene = place(LayoutSpec(objects=(target, mouse), distractors=Distractors(8)),
                      np.random.default_rng(seed), config=cfg, reach=reach).scene
        pose = {o.name: o for o in scene.objects}
        bowl_zone = grasp_zone("bowl", pose["bowl"].scale, pose["bowl"].yaw, pose["bowl"].xy)
        others = [footprint(o.type, o.scale, o.yaw, o.xy) for o in scene.objects if o.name != "bowl"]
        hits += sum(any(f.intersects(z) for z in bowl_zone) for f in others)
        m = pose["mouse"]
        for o in scene.objects:
            if o.name != "mouse":
                assert not any(footprint(o.type, o.scale, o.yaw, o.xy).intersects(z)
                               for z in grasp_zone("mouse", m.scale, m.yaw, m.xy, cfg.finger_slack))
    assert hits > 0  # the bowl's unused zones were not kept free


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


def test_a_plans_layout_marks_what_its_subtasks_grasp():
    from vcage.pipeline.plan_layout import plan_layout
    from vcage.planning import make_planner
    from vcage.planning.config import PlannerConfig

    plan = make_planner(PlannerConfig()).plan("prepare breakfast")
    layout = plan_layout(plan, np.random.default_rng(0), Randomization())
    grasped = {o.name for o in layout.objects if o.grasped}
    picked = {st.args["obj"] for st in plan.subtasks if st.skill == "pick_and_place"}
    assert grasped == picked and len(picked) >= 2
    assert len(grasped) < len(layout.objects)  # the basket, the coaster, the bell are not grasped


def test_what_a_target_receives_finds_room_there(reach):
    from vcage.pipeline.plan_layout import plan_layout
    from vcage.planning import make_planner
    from vcage.planning.config import PlannerConfig
    from vcage.scene.placement.geometry import carry_radius

    plan = make_planner(PlannerConfig()).plan("prepare breakfast")
    puts = {st.args["target"]: st.args["obj"] for st in plan.subtasks
            if st.skill == "pick_and_place" and st.args.get("target")}
    layout = plan_layout(plan, np.random.default_rng(0), Randomization())
    by_name = {o.name: o for o in layout.objects}
    assert puts and all(by_name[t].receives == pytest.approx(carry_radius(by_name[h].type, by_name[h].scale))
                        for t, h in puts.items())
    assert all(o.receives == 0 for o in layout.objects if o.name not in puts)
    # a coaster that will receive a cup, packed among other things: nothing stands in that room
    need = carry_radius("cup", 1.0)
    coaster = LayoutObject("coaster", "coaster", region=AREA, receives=need)
    crowd = (coaster, *(LayoutObject(f"b{i}", "block", region=AREA, grasped=False) for i in range(9)))
    inside = {True: 0, False: 0}
    for zones in (True, False):
        for seed in range(6):
            scene = place(LayoutSpec(objects=crowd), np.random.default_rng(seed),
                          config=PlacementConfig(finger_zones=zones), reach=reach).scene
            pose = {o.name: o for o in scene.objects}
            room = shapely.Point(pose["coaster"].xy).buffer(need, 16)
            inside[zones] += sum(footprint(o.type, o.scale, o.yaw, o.xy).intersects(room)
                                 for o in scene.objects if o.name != "coaster")
    assert inside[True] == 0 < inside[False]


def test_what_rests_in_a_target_keeps_clear_of_the_room_it_receives_in(reach):
    from vcage.errors import PlacementError
    from vcage.scene.layout import Support
    from vcage.scene.placement.geometry import carry_radius

    need = carry_radius("block", 1.0)
    inside = {True: 0, False: 0}
    layout = LayoutSpec(objects=(LayoutObject("tray", "tray", region=AREA, grasped=False, receives=need),
                                 LayoutObject("fries", "block", support=Support("tray"), grasped=False)))
    for zones in (True, False):
        cfg = PlacementConfig(finger_zones=zones)
        for seed in range(8):
            scene = place(layout, np.random.default_rng(seed), config=cfg, reach=reach).scene
            pose = {o.name: o for o in scene.objects}
            room = shapely.Point(pose["tray"].xy).buffer(need, 16)  # the tray's placement is centred
            fries = pose["fries"]
            inside[zones] += footprint(fries.type, fries.scale, fries.yaw, fries.xy).intersects(room)
    assert inside[True] == 0 < inside[False]
    # a basket too small for both what rests in it and the room for a bread: no scene, a typed error
    crowded = LayoutSpec(objects=(
        LayoutObject("basket", "basket", region=AREA, grasped=False, receives=carry_radius("bread", 1.0)),
        LayoutObject("apple", "apple", support=Support("basket"), grasped=False)))
    with pytest.raises(PlacementError, match="basket"):
        place(crowded, np.random.default_rng(0), config=PlacementConfig(), reach=reach)


def _intrusions(layout, reach, host: str, seeds: int, zone_of) -> dict[bool, int]:
    """Footprints entering ``zone_of(host as placed)`` over ``seeds`` placements of ``layout``, with
    finger zones on (True) and off (False)."""
    counts = {True: 0, False: 0}
    for zones in (True, False):
        for seed in range(seeds):
            placed = place(layout, np.random.default_rng(seed), config=PlacementConfig(finger_zones=zones),
                           reach=reach).scene
            zone = zone_of(next(o for o in placed.objects if o.name == host))
            counts[zones] += sum(footprint(o.type, o.scale, o.yaw, o.xy).intersects(zone)
                                 for o in placed.objects if o.name != host)
    return counts


def test_a_drawer_the_plan_slides_faces_the_robot_and_nothing_stands_where_it_comes_out(reach):
    from vcage.pipeline.plan_layout import WORK_AREA, plan_layout
    from vcage.planning import make_planner
    from vcage.planning.config import PlannerConfig
    from vcage.scene.placement.geometry import drawer_zone

    plan = make_planner(PlannerConfig()).plan("clear the washstand")
    layout = plan_layout(plan, np.random.default_rng(0), Randomization(), clutter=6)
    cabinet = next(o for o in layout.objects if o.type == "cabinet")
    assert cabinet.slides == pytest.approx(0.12)
    assert all(o.slides == 0 for o in layout.objects if o is not cabinet)
    assert -0.5 < cabinet.yaw[0] < cabinet.yaw[1] < 0.5  # its handle (on its -x side) towards the robot
    def sweep(cab):
        zone = drawer_zone("cabinet", cab.scale, cab.yaw, 0.12, cab.xy)
        front = cab.xy[0] - (0.1025 + 0.12) * math.cos(cab.yaw)  # the drawer's front, out 12 cm
        assert zone.area > 0.0 and front >= WORK_AREA.bounds[0] - 1e-9
        return zone

    counts = _intrusions(layout, reach, cabinet.name, 6, sweep)
    assert counts[True] == 0 < counts[False]
    # the zone is the drawer's sweep: as wide as the cabinet, from its front towards -x at yaw 0
    z = drawer_zone("cabinet", 1.0, 0.0, 0.12, (0.7, 0.0))
    x0, y0, x1, y1 = z.bounds
    assert x1 == pytest.approx(0.7 - 0.1025) and x0 == pytest.approx(0.7 - 0.1025 - 0.12 - R.FINGER_OUTER)
    assert (y0, y1) == (pytest.approx(-0.11), pytest.approx(0.11))


def test_a_rack_the_plan_hangs_a_mug_on_turns_its_peg_to_the_robots_right_with_room_at_its_end(reach):
    """The peg's free end points to the robot's right (as hanging_mug's rack stands), and nothing
    stands within the hung mug's reach of it; with finger zones off, something does."""
    from vcage.pipeline.plan_layout import plan_layout
    from vcage.planning import make_planner
    from vcage.planning.config import PlannerConfig
    from vcage.scene.placement.geometry import carry_radius

    plan = make_planner(PlannerConfig()).plan("tidy the coffee corner")
    layout = plan_layout(plan, np.random.default_rng(0), Randomization(), clutter=8)
    rack = next(o for o in layout.objects if o.type == "mug_rack")
    mug = next(o for o in layout.objects if o.type == "mug")
    assert rack.hangs == pytest.approx(carry_radius("mug", mug.scale))
    assert all(o.hangs == 0 for o in layout.objects if o is not rack)
    assert -0.7 < rack.yaw[0] < rack.yaw[1] < 0.7  # its free end (rack frame -y) towards world -y
    def room(r):
        end = (r.xy[0] + 0.06 * math.sin(r.yaw), r.xy[1] - 0.06 * math.cos(r.yaw))  # rack (0, -0.06)
        return shapely.Point(end).buffer(rack.hangs)

    counts = _intrusions(layout, reach, rack.name, 8, room)
    assert counts[True] == 0 < counts[False]
