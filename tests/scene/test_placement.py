"""Context-aware placement, its baselines, and the layouts they refuse."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
import shapely
from shapely.geometry import Point

from vcage.errors import CatalogError, PlacementError
from vcage.scene.layout import (
    Distractors,
    LayoutObject,
    LayoutSpec,
    Region,
    Relation,
    ReservedZone,
    Support,
)
from vcage.scene.placement import PlacementConfig, place
from vcage.scene.placement.geometry import footprint, minkowski_cobstacle, sample_point
from vcage.scene.spec import ROBOT_MOUNT
from vcage.skills.reachability import reach_map


@pytest.fixture(scope="module")
def reach():
    return reach_map()


def _footprints(scene, table_only=True):
    return {o.name: footprint(o.type, o.scale, o.yaw, o.xy) for o in scene.objects
            if not table_only or o.z is None or o.z < scene.table.height + 0.01}


@pytest.mark.parametrize("count", [5, 20])
def test_context_scenes_never_overlap_and_stay_reachable(reach, count):
    cfg = PlacementConfig()
    for seed in range(5):
        result = place(LayoutSpec(distractors=Distractors(count)), np.random.default_rng(seed),
                       reach=reach)
        shapes = _footprints(result.scene)
        assert len(shapes) == count and result.stats.placed == count
        for (a, pa), (b, pb) in itertools.combinations(shapes.items(), 2):
            assert pa.distance(pb) >= cfg.margin - 1e-6, (seed, a, b)
        r_in, r_out = reach.interval(result.scene.table.height)
        table = shapely.box(0.15 + cfg.edge_margin, -0.6 + cfg.edge_margin, 0.95 - cfg.edge_margin,
                            0.6 - cfg.edge_margin)
        for obj in result.scene.objects:
            assert table.covers(shapes[obj.name])
            assert r_in - 1e-3 <= math.hypot(*obj.xy) <= r_out + 1e-3


def test_same_seed_same_scene(reach):
    layout = LayoutSpec(distractors=Distractors(12))
    a = place(layout, np.random.default_rng(3), reach=reach).scene
    b = place(layout, np.random.default_rng(3), reach=reach).scene
    c = place(layout, np.random.default_rng(4), reach=reach).scene
    assert a == b and a != c


def test_relations_and_regions_hold(reach):
    objs = (LayoutObject("pad", "mouse_pad", region=Region((0.5, 0.0), (0.05, 0.05))),
            LayoutObject("cup", "cup"), LayoutObject("bell", "bell"), LayoutObject("can", "can"),
            LayoutObject("apple", "apple"))
    rels = (Relation("left_of", "cup", "pad", 0.05), Relation("right_of", "bell", "pad", 0.05),
            Relation("near", "can", "pad", 0.2), Relation("far_from", "apple", "pad", 0.3))
    for seed in range(8):
        scene = place(LayoutSpec(objects=objs, relations=rels, distractors=Distractors(6)),
                      np.random.default_rng(seed), reach=reach).scene
        pos = {o.name: np.asarray(o.xy) for o in scene.objects}
        assert abs(pos["pad"][0] - 0.5) <= 0.05 + 1e-9 and abs(pos["pad"][1]) <= 0.05 + 1e-9
        assert pos["cup"][1] >= pos["pad"][1] + 0.05
        assert pos["bell"][1] <= pos["pad"][1] - 0.05
        assert np.linalg.norm(pos["can"] - pos["pad"]) <= 0.2
        assert np.linalg.norm(pos["apple"] - pos["pad"]) >= 0.3


def test_reserved_zone_stays_free(reach):
    zone = Region((0.5, 0.0), (0.1, 0.25))
    for seed in range(5):
        scene = place(LayoutSpec(reserved=(ReservedZone("target", zone),),
                                 distractors=Distractors(15)), np.random.default_rng(seed),
                      reach=reach).scene
        for shape in _footprints(scene).values():
            assert not shape.intersects(shapely.box(*zone.bounds))


def test_tall_distractors_keep_clear_of_task_objects(reach):
    cfg = PlacementConfig()
    task = LayoutObject("mouse", "mouse", region=Region((0.5, 0.0), (0.02, 0.02)))
    for seed in range(5):
        scene = place(LayoutSpec(objects=(task,), distractors=Distractors(20, max_size=0.3)),
                      np.random.default_rng(seed), reach=reach).scene
        shapes = _footprints(scene)
        for obj in scene.objects[1:]:
            from vcage.assets.catalog import CATALOG
            tall = CATALOG.get(obj.type).size[2] * obj.scale > cfg.tall_height
            need = cfg.margin + (cfg.tall_clearance if tall else cfg.task_clearance)
            assert shapes[obj.name].distance(shapes["mouse"]) >= need - 1e-6


def test_supports_put_objects_on_and_inside_others(reach):
    objs = (LayoutObject("basket", "basket", region=Region((0.5, 0.1))),
            LayoutObject("bread", "bread", support=Support("basket")),
            LayoutObject("b1", "block", region=Region((0.5, -0.15))),
            LayoutObject("b2", "block", support=Support("b1", "top"), yaw=(0.0, 0.0)))
    scene = place(LayoutSpec(objects=objs), np.random.default_rng(0), reach=reach).scene
    bread, b2, b1 = scene.object("bread"), scene.object("b2"), scene.object("b1")
    assert bread.z is not None and b2.z is not None
    assert abs(b2.z - (scene.table.height + 0.045 + 0.002)) < 1e-3
    assert np.linalg.norm(np.subtract(b2.xy, b1.xy)) <= 0.0225 * math.sqrt(2) + 1e-9
    assert np.max(np.abs(np.subtract(bread.xy, (0.5, 0.1)))) <= 0.1


def test_pinned_positions_are_kept_exactly_or_refused(reach):
    a = LayoutObject("a", "block", region=Region((0.5, 0.0)), yaw=(0.3, 0.3))
    scene = place(LayoutSpec(objects=(a,)), np.random.default_rng(0), reach=reach).scene
    assert scene.object("a").xy == (0.5, 0.0) and scene.object("a").yaw == 0.3
    b = LayoutObject("b", "block", region=Region((0.52, 0.0)))
    with pytest.raises(PlacementError, match="'b'"):
        place(LayoutSpec(objects=(a, b)), np.random.default_rng(0), reach=reach)


def test_impossible_density_fails_fast_with_the_free_area(reach):
    with pytest.raises(PlacementError, match=r"no free space for 'clutter\d+_\w+'.*on table: .* m²"):
        place(LayoutSpec(distractors=Distractors(150)), np.random.default_rng(0), reach=reach)


def test_backtracking_is_bounded_and_counted(reach):
    # Dense enough that some seeds need to re-place distractors, never more than the bound.
    cfg = PlacementConfig(max_backtracks=3)
    for seed in range(5):
        try:
            result = place(LayoutSpec(distractors=Distractors(40, max_size=0.3)),
                           np.random.default_rng(seed), config=cfg, reach=reach)
        except PlacementError as exc:
            assert "backtracks" in str(exc)
            continue
        assert result.stats.backtracks <= 3


@pytest.mark.parametrize("bad, message", [
    (LayoutSpec(objects=(LayoutObject("b", "block"), LayoutObject("pot", "pot", support=Support("b")))),
     "too large to stand on 'b'"),
    (LayoutSpec(objects=(LayoutObject("c", "cup"), LayoutObject("bowl", "bowl", support=Support("c")))),
     "too large to stand inside 'c'"),
    (LayoutSpec(objects=(LayoutObject("a", "block"), LayoutObject("b", "block")),
                relations=(Relation("left_of", "a", "b"), Relation("right_of", "a", "b"))),
     "cannot be both left_of and right_of"),
    (LayoutSpec(objects=(LayoutObject("a", "block"), LayoutObject("b", "block")),
                relations=(Relation("left_of", "a", "b"), Relation("left_of", "b", "a"))),
     "cannot be both left_of and right_of"),
    (LayoutSpec(objects=(LayoutObject("a", "block"), LayoutObject("b", "block")),
                relations=(Relation("near", "a", "b", 0.1), Relation("far_from", "b", "a", 0.2))),
     "within 0.1 m and beyond 0.2 m"),
    (LayoutSpec(objects=(LayoutObject("a", "block"),),
                reserved=(ReservedZone("all", Region((0.55, 0.0), (0.5, 0.7))),)),
     "cover 100% of the table"),
    (LayoutSpec(objects=(LayoutObject("a", "block", region=Region((2.0, 0.0))),)), "off the table"),
    (LayoutSpec(objects=(LayoutObject("a", "block", support=Support("b")),
                         LayoutObject("b", "block", support=Support("a")))), "cycle"),
])
def test_impossible_layouts_are_refused_before_sampling(reach, bad, message):
    with pytest.raises(PlacementError, match=message):
        place(bad, np.random.default_rng(0), reach=reach)


def test_unknown_types_and_methods_list_the_valid_ones(reach):
    with pytest.raises(CatalogError, match="block"):
        place(LayoutSpec(objects=(LayoutObject("x", "unicorn"),)), np.random.default_rng(0))
    with pytest.raises(Exception, match="context, naive, rejection"):
        place(LayoutSpec(), np.random.default_rng(0), method="magic")


def test_baselines_share_the_interface(reach):
    layout = LayoutSpec(distractors=Distractors(10))
    naive = place(layout, np.random.default_rng(1), method="naive").scene
    rejection = place(layout, np.random.default_rng(1), method="rejection").scene
    assert [o.type for o in naive.objects] == [o.type for o in rejection.objects]
    # rejection keeps bounding circles apart; naive checks nothing
    from vcage.assets.catalog import CATALOG
    for a, b in itertools.combinations(rejection.objects, 2):
        ra = CATALOG.get(a.type).footprint_radius * a.scale
        rb = CATALOG.get(b.type).footprint_radius * b.scale
        assert np.linalg.norm(np.subtract(a.xy, b.xy)) > ra + rb
    with pytest.raises(PlacementError, match="in 50 tries"):
        place(LayoutSpec(distractors=Distractors(60)), np.random.default_rng(0), method="rejection",
              config=PlacementConfig(rejection_tries=50))


def test_geometry_helpers():
    square = shapely.box(-0.1, -0.1, 0.1, 0.1)
    probe = footprint("block", 1.0, 0.0)
    c = minkowski_cobstacle(square, probe)
    half = 0.045 / 2
    assert c.bounds == pytest.approx((-0.1 - half, -0.1 - half, 0.1 + half, 0.1 + half))
    ring = Point(0, 0).buffer(1.0).difference(Point(0, 0).buffer(0.5))
    rng = np.random.default_rng(0)
    pts = np.array([sample_point(ring, rng) for _ in range(400)])
    radii = np.linalg.norm(pts, axis=1)
    assert np.all((radii >= 0.5 - 1e-9) & (radii <= 1.0 + 1e-9))
    # uniform over area: about (0.75² − 0.5²)/(1 − 0.5²) = 42% fall inside radius 0.75
    assert 0.34 < np.mean(radii < 0.75) < 0.50
    assert sample_point(shapely.Polygon(), rng) is None


def test_reach_map_is_an_interval_around_the_workspace(reach, tmp_path, monkeypatch):
    r_in, r_out = reach.interval(ROBOT_MOUNT[2])
    assert 0.2 < r_in < 0.4 and 0.7 < r_out < 0.85
    from vcage.scene.placement.reach import ReachMap
    path = tmp_path / "reach.json"
    reach.save(path)
    assert ReachMap.from_json(path.read_text()) == reach
