"""The built-in catalog: metadata, queries, and every type checked in real MuJoCo physics."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pytest

from vcage.assets.catalog import CATALOG, ObjectType
from vcage.assets.objects.blocks import BLOCK
from vcage.errors import CatalogError
from vcage.geometry import tilt_of
from vcage.scene.compose import compose
from vcage.scene.spec import ObjectSpec, SceneSpec, TableSpec
from vcage.sim.world import World

TABLE_Z = TableSpec().height
XY = (0.55, 0.25)  # away from the robot
XY_2 = (0.55, -0.25)
MAX_GRASP_WIDTH = 0.065
PALM_ABOVE_TCP = 0.045  # the Panda's palm is ~47 mm above the grasp point (between the pads)
PRESS_FORCE = 10.0  # N, pushed along the functional point's direction
ALL = CATALOG.names()
# a drawer's inside is filled through its opening, not from above (its task puts an object in)
CONTAINERS = [o.name for o in CATALOG.values()
              if any(p.kind == "in" for p in o.placements) and "articulated" not in o.tags]
PRESSABLE = [o.name for o in CATALOG.values() if any(f.joint for f in o.functional_points)]


def _world(*objects: ObjectSpec) -> World:
    return compose(SceneSpec(objects=tuple(objects))).make_world()


def _in_size_box(otype: ObjectType, pos: Sequence[float], tol: float = 1e-6) -> bool:
    sx, sy, sz = otype.size
    return (abs(pos[0]) <= sx / 2 + tol and abs(pos[1]) <= sy / 2 + tol
            and -tol <= pos[2] <= sz + tol)


# -- catalog metadata and queries -------------------------------------------------------------------
def test_catalog_size_and_categories() -> None:
    assert len(CATALOG) >= 30
    assert {"container", "device", "food", "office", "toy"} <= set(CATALOG.categories())
    assert "block" in CATALOG and "mouse" in CATALOG and "dragon" not in CATALOG


def test_queries_by_name_category_and_tag() -> None:
    assert CATALOG.get("cup").name == "cup"
    containers = {o.name for o in CATALOG.by_category("container")}
    assert {"cup", "bowl", "basket", "pot"} <= containers
    devices = {o.name for o in CATALOG.by_category("device")}
    assert {"bell", "alarm_clock", "stapler", "switch"} <= devices
    assert {"apple", "banana", "can"} <= {o.name for o in CATALOG.by_tag("food")}
    assert {o.name for o in CATALOG.by_tag("pressable")} == set(PRESSABLE)
    assert CATALOG.by_tag("no-such-tag") == []


def test_unknown_names_list_the_valid_ones() -> None:
    with pytest.raises(CatalogError) as err:
        CATALOG.get("teapot_xl")
    message = str(err.value)
    assert "teapot_xl" in message and "mug" in message and "bell" in message
    with pytest.raises(CatalogError, match="container"):
        CATALOG.by_category("vehicles")
    with pytest.raises(CatalogError, match="inside"):
        CATALOG.get("cup").placement("on_top")
    with pytest.raises(CatalogError, match="yellow"):
        CATALOG.get("mug").color("plaid")


REQUIRED = {
    # type: (grasp names, {placement: kind}, {functional point: (kind, joint)})
    "mouse": ({"top"}, {}, {}),
    "mouse_pad": (set(), {"top": "on"}, {}),
    "bell": (set(), {}, {"button": ("button", "button")}),
    "alarm_clock": (set(), {}, {"button": ("button", "button")}),
    "stapler": (set(), {}, {"press": ("lever", "arm")}),
    "switch": (set(), {}, {"on": ("switch", "toggle")}),
    "seal": ({"handle"}, {}, {}),
    "stamp_mat": (set(), {"top": "on"}, {}),
    "can": ({"side"}, {}, {}),
    "pot": ({"handle_left", "handle_right"}, {"inside": "in"}, {}),
    "cup": ({"rim"}, {"inside": "in"}, {}),
    "coaster": (set(), {"top": "on"}, {}),
    "bowl": ({"rim"}, {"inside": "in"}, {}),
    "basket": (set(), {"inside": "in"}, {}),
    "bread": ({"top"}, {}, {}),
    "phone": ({"top"}, {}, {}),
    "phone_stand": (set(), {"slot": "on"}, {}),
    "playing_card": (set(), {}, {}),
    "object_stand": (set(), {"top": "on"}, {}),
    # the RoboTwin-style tasks' objects
    "hammer": ({"handle"}, {}, {"head": ("striker", None)}),
    "roller": ({"barrel"}, {}, {}),
    "qr_board": ({"board"}, {}, {"code": ("display", None)}),
    "fan": ({"head"}, {}, {"outlet": ("outlet", None)}),
    "shoe": ({"upper"}, {}, {}),
    "shoe_box": (set(), {"inside": "in"}, {}),
    "pill_bottle": ({"body"}, {}, {}),
    "burger": ({"top"}, {}, {}),
    "fries": ({"carton"}, {}, {}),
    "plastic_box": (set(), {"inside": "in"}, {}),
    "dustbin": (set(), {"inside": "in"}, {}),
    "kitchen_scale": (set(), {"top": "on"}, {}),
    "card_deck": (set(), {}, {}),
    "cabinet": (set(), {"inside": "in"}, {"handle": ("handle", "drawer")}),
    "mug_rack": (set(), {}, {"peg": ("hook", None)}),
}


@pytest.mark.parametrize("name", sorted(REQUIRED))
def test_required_types_and_annotations(name: str) -> None:
    otype = CATALOG.get(name)
    grasps, placements, points = REQUIRED[name]
    assert grasps <= {g.name for g in otype.grasps}
    for pname, kind in placements.items():
        assert otype.placement(pname).kind == kind
    for fname, (kind, joint) in points.items():
        fp = otype.functional_point(fname)
        assert (fp.kind, fp.joint) == (kind, joint)
        assert fp.travel > 0 if joint else abs(float(np.linalg.norm(fp.direction)) - 1.0) < 1e-9


def test_required_details() -> None:
    bell = CATALOG.get("bell")
    assert not bell.fixed and bell.functional_point("button").travel == pytest.approx(0.004)
    assert 2 * 0.03 <= CATALOG.get("can").size[0] <= 2 * 0.034
    pot = CATALOG.get("pot")
    assert 0.18 <= pot.size[0] <= 0.22 and 0.08 <= pot.size[2] <= 0.12 and pot.mass <= 0.5
    assert CATALOG.get("cup").size[0] <= 0.07
    assert CATALOG.get("mouse_pad").size[2] <= 0.006
    inner = CATALOG.get("basket").placement("inside")
    assert inner.half_size[0] >= 0.085 and inner.half_size[1] >= 0.065
    assert CATALOG.get("playing_card").size[2] <= 0.004
    assert CATALOG.get("phone").size[2] <= 0.012


@pytest.mark.parametrize("name", ALL)
def test_metadata_is_consistent(name: str) -> None:
    otype = CATALOG.get(name)
    assert otype.description and 0 < otype.mass <= 1.0
    assert all(0.0 < s <= 0.35 for s in otype.size)
    assert 1 <= len(otype.colors) <= 6
    for rgba in otype.colors.values():
        assert len(rgba) == 4 and all(0.0 <= c <= 1.0 for c in rgba)
    assert ("graspable" in otype.tags) == bool(otype.grasps)
    assert ("container" in otype.tags) == any(p.kind == "in" for p in otype.placements)
    assert ("pressable" in otype.tags) == any(f.joint for f in otype.functional_points)
    assert otype.annotations.stable_orientations
    for q in (s.quat for s in otype.annotations.stable_orientations):
        assert math.isclose(float(np.linalg.norm(q)), 1.0, abs_tol=1e-6)


@pytest.mark.parametrize("name", ALL)
def test_annotations_fit_the_object(name: str) -> None:
    otype = CATALOG.get(name)
    for g in otype.grasps:
        assert 0 < g.width <= MAX_GRASP_WIDTH, g
        assert _in_size_box(otype, g.pos), g
        if name != "phone":  # the fingers reach ~35 mm below the grasp point
            assert g.pos[2] >= 0.02 - 1e-9, g
        assert g.pos[2] + PALM_ABOVE_TCP >= otype.size[2], g  # the palm clears the top
    for p in otype.placements:
        assert p.kind in ("on", "in") and _in_size_box(otype, p.pos), p
        assert all(h > 0 for h in p.half_size)
        assert abs(p.pos[0]) + p.half_size[0] <= otype.size[0] / 2 + 1e-6
        assert abs(p.pos[1]) + p.half_size[1] <= otype.size[1] / 2 + 1e-6
        if p.kind == "in":
            assert 0 < p.pos[2] + p.wall_height <= otype.size[2] + 1e-6
    for f in otype.functional_points:
        assert _in_size_box(otype, f.pos), f


# -- physics: every type rests where it is put ------------------------------------------------------
@pytest.mark.parametrize("name", ALL)
def test_type_composes_and_rests(name: str) -> None:
    otype = CATALOG.get(name)
    lo, hi = otype.scale_range
    world = _world(ObjectSpec("a", name, XY, scale=lo),
                   ObjectSpec("b", name, XY_2, yaw=0.7, scale=hi, color=list(otype.colors)[-1]))
    start = {n: world.object_pos(n) for n in ("a", "b")}
    world.settle(1.0)
    for n in ("a", "b"):
        pos = world.object_pos(n)
        assert np.linalg.norm(pos[:2] - start[n][:2]) < 0.01, (n, pos, start[n])
        assert pos[2] >= TABLE_Z - 0.002, (n, pos)
        assert tilt_of(world.object_mat(n)) < 0.1, n
    geoms = [world.model.geom(i).name for i in range(world.model.ngeom)]
    assert any(g.startswith("a/") for g in geoms) and any(g.startswith("b/") for g in geoms)


@pytest.mark.parametrize("name", CONTAINERS)
def test_container_holds_a_dropped_block(name: str) -> None:
    otype = CATALOG.get(name)
    place = next(p for p in otype.placements if p.kind == "in")
    # Narrow containers (a cup) get a smaller block: its footprint must fit the placement square.
    scale = min(1.0, 0.9 * min(place.half_size) / (BLOCK / 2))
    drop = (XY[0] + place.pos[0], XY[1] + place.pos[1])
    world = _world(ObjectSpec("box", name, XY),
                   ObjectSpec("blk", "block", drop, scale=scale, z=TABLE_Z + place.pos[2] + 0.05))
    world.settle(1.5)
    box, blk = world.object_pos("box"), world.object_pos("blk")
    rel = blk - box
    assert abs(rel[0] - place.pos[0]) <= place.half_size[0], rel
    assert abs(rel[1] - place.pos[1]) <= place.half_size[1], rel
    assert place.pos[2] - 0.003 <= rel[2] < place.pos[2] + place.wall_height, rel  # block bottom
    assert tilt_of(world.object_mat("box")) < 0.1


def test_bowls_nest() -> None:
    bowl = CATALOG.get("bowl")
    world = _world(ObjectSpec("outer", "bowl", XY),
                   ObjectSpec("inner", "bowl", XY, z=TABLE_Z + 0.03, color="blue"))
    world.settle(1.5)
    outer, inner = world.object_pos("outer"), world.object_pos("inner")
    assert np.linalg.norm(inner[:2] - outer[:2]) < 0.01
    assert inner[2] - outer[2] < 0.5 * bowl.size[2]  # sits down inside, not on the rim
    assert tilt_of(world.object_mat("inner")) < 0.1 and tilt_of(world.object_mat("outer")) < 0.1


# -- articulated devices ----------------------------------------------------------------------------
def _press(world: World, instance: str, point: str, seconds: float = 0.3) -> tuple[str, float, float]:
    """Push on a functional point's moving body; returns the joint name, its rest value, and the
    largest displacement seen while pushing."""
    otype = CATALOG.get(world.object(instance).type_name)
    fp = otype.functional_point(point)
    joint = f"{instance}/{fp.joint}"
    model, data = world.model, world.data
    body = int(model.joint(joint).bodyid[0])
    q0 = world.joint_value(joint)
    p_world = world.object_pos(instance) + world.object_mat(instance) @ np.asarray(fp.pos)
    rot = data.xmat[body].reshape(3, 3)
    p_local = rot.T @ (p_world - data.xpos[body])
    force = PRESS_FORCE * np.asarray(fp.direction)
    moved = 0.0
    for _ in range(max(1, round(seconds / world.control_dt))):
        p_now = data.xpos[body] + data.xmat[body].reshape(3, 3) @ p_local
        data.xfrc_applied[body, :3] = force
        data.xfrc_applied[body, 3:] = np.cross(p_now - data.xipos[body], force)
        world.step()
        moved = max(moved, abs(world.joint_value(joint) - q0))
    data.xfrc_applied[body] = 0.0
    return joint, q0, moved


@pytest.mark.parametrize("name", PRESSABLE)
def test_pressing_the_functional_point_moves_its_joint(name: str) -> None:
    otype = CATALOG.get(name)
    fp = otype.functional_points[0]
    world = _world(ObjectSpec(name, name, XY))
    joint = f"{name}/{fp.joint}"
    assert world.model.joint(joint).name == joint
    world.settle(1.0)
    rest = world.joint_value(joint)
    world.settle(0.3)
    assert abs(world.joint_value(joint) - rest) < 0.1 * fp.travel  # at rest under gravity
    spring_ref = world.model.qpos_spring[world.model.joint(joint).qposadr[0]]
    assert abs(rest - spring_ref) < 0.1 * fp.travel  # the spring reference is the rest value
    start = world.object_pos(name)
    _, q0, moved = _press(world, name, fp.name)
    assert moved >= fp.travel, (moved, fp.travel)
    world.settle(0.7)
    after = world.joint_value(joint)
    if fp.kind in ("switch", "handle"):  # bistable, or a drawer with no spring: stays where moved
        assert abs(after - q0) >= fp.travel, after
    else:  # spring-loaded: comes back
        assert abs(after - q0) < 0.25 * fp.travel, (after, q0)
    assert np.linalg.norm(world.object_pos(name)[:2] - start[:2]) < 0.01


def test_switch_toggles_both_ways() -> None:
    world = _world(ObjectSpec("sw", "switch", XY))
    world.settle(0.5)
    joint, off, _ = _press(world, "sw", "on")
    world.settle(0.5)
    on = world.joint_value(joint)
    assert on > 0.1 > -0.1 > off
    _, _, moved = _press(world, "sw", "off")
    world.settle(0.5)
    assert moved >= 0.3 and world.joint_value(joint) == pytest.approx(off, abs=0.03)


def test_button_does_not_sag_and_survives_scaling() -> None:
    world = _world(ObjectSpec("big", "bell", XY, scale=1.05),
                   ObjectSpec("clock", "alarm_clock", XY_2, scale=0.9))
    world.settle(1.0)
    for joint in ("big/button", "clock/button"):
        assert abs(world.joint_value(joint)) < 2e-4
