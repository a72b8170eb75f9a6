"""The oracle's negative cases: what must *not* count as a press, inside, released, left/right, near.

The oracle labels every critic figure, so a predicate that holds too easily would make every
critic look better than it is. Each case below is a real MuJoCo state (settled, or reached by the
skills), never a flag set by hand.
"""

from __future__ import annotations

import numpy as np

from vcage.assets.catalog import CATALOG
from vcage.planning.schema import Predicate
from vcage.scene.compose import compose
from vcage.scene.spec import ObjectSpec, SceneSpec
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.skills.faults import FaultConfig, FaultInjector
from vcage.skills.placements import placement_frame
from vcage.tasks.oracle import Oracle
from vcage.tasks.predicates import ORACLE_CHECKS, joint_displacement

PRESSED = Predicate(name="pressed", args=("bell",))


def _composed(*objects: ObjectSpec) -> World:
    return compose(SceneSpec(objects=objects)).make_world()


def _settled(*objects: ObjectSpec) -> World:
    world = _composed(*objects)
    world.settle(0.5)
    return world


def _value(world: World, name: str, *args: str) -> bool:
    return ORACLE_CHECKS.get(name)(world, *args)


def _watched(skills: Skills) -> Oracle:
    oracle = Oracle()
    skills.player.hooks.append(oracle.on_step)
    oracle.begin([PRESSED])
    return oracle


def test_a_press_latches_and_stays_latched_after_the_button_springs_back() -> None:
    world = _settled(ObjectSpec("bell", "bell", (0.55, 0.05)))
    skills = Skills(world)
    oracle = _watched(skills)
    skills.do("press", obj="bell")
    skills.do("retreat")
    assert not _value(world, "pressed", "bell")  # the button is back up ...
    assert oracle.check(world, [PRESSED]) == {"pressed(bell)": True}  # ... but it was pressed


def test_a_light_press_a_hover_and_a_press_before_watching_do_not_count() -> None:
    for fault in ("press_light", "press_hover"):
        world = _settled(ObjectSpec("bell", "bell", (0.55, 0.05)))
        skills = Skills(world, fault=FaultInjector(FaultConfig(fault, "press")))
        oracle = _watched(skills)
        skills.do("press", obj="bell")
        assert oracle.check(world, [PRESSED]) == {"pressed(bell)": False}, fault
    world = _settled(ObjectSpec("bell", "bell", (0.55, 0.05)))
    skills = Skills(world)
    oracle = Oracle()
    skills.player.hooks.append(oracle.on_step)
    skills.do("press", obj="bell")  # pressed before the subtask began
    oracle.begin([PRESSED])
    skills.do("retreat")
    assert oracle.check(world, [PRESSED]) == {"pressed(bell)": False}
    assert Oracle().check(world, [PRESSED]) == {"pressed(bell)": False}  # never watched


def test_a_button_held_down_by_a_loaf_lying_on_it_is_not_pressed_by_the_robot() -> None:
    """Vanilla put loaves on bells: the loaf's weight holds the button down its travel, and the hand
    pressing the bell meets the loaf, not the bell. The button went down, but the robot did not
    press the bell; pressed straight, the same bell is."""
    scene = (ObjectSpec("bell", "bell", (0.55, 0.05)), ObjectSpec("bread", "bread", (0.55, 0.05), z=0.83))
    world = _settled(*scene)
    button = CATALOG.get("bell").functional_point(None)
    assert joint_displacement(world, "bell", button.joint) >= button.travel  # held down at rest
    assert not _value(world, "pressed", "bell")
    skills = Skills(world)
    oracle = _watched(skills)
    skills.do("press", obj="bell")
    assert oracle.check(world, [PRESSED]) == {"pressed(bell)": False}
    world = _settled(scene[0])
    skills = Skills(world)
    oracle = _watched(skills)
    skills.do("press", obj="bell")
    assert oracle.check(world, [PRESSED]) == {"pressed(bell)": True}


def test_inside_needs_the_region_and_the_height_below_the_rim() -> None:
    beside = _settled(ObjectSpec("bread", "bread", (0.5, -0.08)), ObjectSpec("basket", "basket", (0.5, 0.1)))
    assert not _value(beside, "inside", "bread", "basket")
    inside = _settled(ObjectSpec("bread", "bread", (0.5, 0.1), z=0.78),
                      ObjectSpec("basket", "basket", (0.5, 0.1)))
    assert _value(inside, "inside", "bread", "basket")
    above = _composed(ObjectSpec("bread", "bread", (0.5, 0.1), z=0.95),
                      ObjectSpec("basket", "basket", (0.5, 0.1)))
    above.forward()  # held over the basket, in its region but above the rim
    assert not _value(above, "inside", "bread", "basket")


def _posed(world: World, name: str, pose: list[float]) -> None:
    """Put ``name``'s free joint at ``pose`` (x, y, height above the table top, quaternion)."""
    adr = int(world.model.jnt_qposadr[world.model.joint(f"{name}/free").id])
    world.data.qpos[adr:adr + 7] = [pose[0], pose[1], world.table_top() + pose[2], *pose[3:]]


def test_a_loaf_wedged_under_a_tipped_baskets_edge_is_not_inside_it() -> None:
    """The poses of a loaf and a basket after a Vanilla rollout (prepare_breakfast, episode 12): the
    loaf lies against the basket's outer wall, under its raised edge. Its origin (the centre of its
    base) lies within a centimetre of the basket's region and level with its floor, which the
    oracle once took for inside."""
    world = _composed(ObjectSpec("bread", "bread", (0.2, 0.3), scale=0.9506),
                      ObjectSpec("basket", "basket", (0.5, 0.1), scale=1.0231))
    _posed(world, "bread", [0.5842, -0.2663, 0.0127, 0.3706, 0.0692, -0.059, 0.9243])
    _posed(world, "basket", [0.5484, -0.1746, 0.0138, 0.5757, -0.0575, 0.0415, 0.8146])
    world.forward()
    assert not _value(world, "inside", "bread", "basket")


def test_a_loaf_standing_on_end_in_a_basket_is_inside_it() -> None:
    """A loaf upended in a basket has its origin (the centre of its base, now a side) above the rim;
    its lowest point lies on the floor and its centre of mass within the walls."""
    on_end = [np.cos(np.pi / 4), 0.0, np.sin(np.pi / 4), 0.0]  # 90 degrees about y: long axis up
    world = _composed(ObjectSpec("bread", "bread", (0.2, 0.3)),
                      ObjectSpec("basket", "basket", (0.5, 0.1)))
    _posed(world, "bread", [0.5 - 0.034, 0.1, 0.08, *on_end])
    world.forward()
    world.settle(0.5)
    assert world.object_pos("bread")[2] - world.table_top() > 0.06  # the origin stands above the rim
    assert _value(world, "inside", "bread", "basket")


def test_a_loaf_lying_across_a_cups_rim_is_not_inside_it() -> None:
    """Its centre of mass is over the cup's opening and its lowest point at the rim's height: lying
    on the rim is not lying in the cup (injected faults left a soap and a sponge so on a drawer's
    front wall, the lowest-point rule without the rim's contact tolerance took them for inside)."""
    world = _settled(ObjectSpec("cup", "cup", (0.5, 0.1)), ObjectSpec("bread", "bread", (0.5, 0.1), z=0.85))
    center, rot, _, wall = placement_frame(world, "cup")
    assert abs(world.object_lowest("bread", rot[:, 2], center) - wall) < 0.002  # it rests on the rim
    assert not _value(world, "inside", "bread", "cup")


def test_the_lowest_point_of_an_object_is_where_it_meets_the_table() -> None:
    """:meth:`World.object_lowest` for boxes, capsules, cylinders and spheres, upright or tipped."""
    world = _settled(ObjectSpec("block", "block", (0.5, -0.15)), ObjectSpec("bread", "bread", (0.5, 0.1)),
                     ObjectSpec("can", "can", (0.65, -0.1)), ObjectSpec("mouse", "mouse", (0.4, 0.25)),
                     ObjectSpec("ball", "tennis_ball", (0.35, -0.2)))
    up, origin = np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, world.table_top()])
    for name in ("block", "bread", "can", "mouse", "ball"):
        assert abs(world.object_lowest(name, up, origin)) < 0.002, name
    _posed(world, "can", [0.65, -0.1, 0.2, np.cos(0.6), np.sin(0.6), 0.0, 0.0])  # tipped and lifted
    world.forward()
    world.settle(1.0)  # falls and lies on its side, then rolls still
    assert abs(world.object_lowest("can", up, origin)) < 0.002


def test_on_a_tipped_block_is_not_beside_it() -> None:
    """Two blocks knocked onto their sides, side by side, are not a tower (seen in a Vanilla rollout,
    where the oracle once took the placement frame of a block on its side, which lay beside it)."""
    world = _composed(ObjectSpec("base", "block", (0.55, 0.0)),
                      ObjectSpec("middle", "block", (0.55, 0.1)))
    half, turn = 0.0225, [np.cos(-np.pi / 4), np.sin(-np.pi / 4), 0.0, 0.0]  # 90 degrees about x
    for name, y in (("base", -half), ("middle", half + 0.002)):  # both on their sides, side by side
        adr = int(world.model.jnt_qposadr[world.model.joint(f"{name}/free").id])
        world.data.qpos[adr:adr + 7] = [0.55, y, world.table_top() + half, *turn]
    world.forward()
    world.settle(0.5)
    assert all(abs(world.object_mat(n)[2, 2]) < 0.1 for n in ("base", "middle"))  # on their sides
    assert not _value(world, "on", "middle", "base")
    tower = _settled(ObjectSpec("base", "block", (0.55, 0.0)),
                     ObjectSpec("middle", "block", (0.55, 0.0), z=0.79))
    assert _value(tower, "on", "middle", "base")


def test_a_block_on_a_block_lying_on_its_side_is_on_it() -> None:
    """A cube's faces are all alike: a Vanilla rollout stacked a block on a middle block that had
    turned onto its side on the base, a tower of three that the oracle once denied."""
    world = _settled(ObjectSpec("base", "block", (0.55, 0.0)), ObjectSpec("middle", "block", (0.3, 0.2)),
                     ObjectSpec("top", "block", (0.55, 0.0), z=0.95))
    half, turn = 0.0225, np.array([np.cos(-np.pi / 4), np.sin(-np.pi / 4), 0.0, 0.0])  # 90 degrees about x
    _posed(world, "middle", [0.55, -half, 3 * half + 0.001, *turn])  # its origin (base's centre) at the side
    _posed(world, "top", [0.555, 0.0, 4 * half + 0.002, 1.0, 0.0, 0.0, 0.0])
    world.forward()
    world.settle(0.5)
    assert abs(world.object_mat("middle")[2, 2]) < 0.1  # on its side
    assert _value(world, "on", "top", "middle") and _value(world, "stacked", "base", "middle", "top")
    assert not _value(world, "on", "top", "base")


def test_a_die_rests_on_the_stand_on_whichever_face_is_down() -> None:
    """A die turned over on the stand rests on it, though its origin (the centre of its "1" face) is a
    whole side above the stand's top; on its side, half a side. Its lowest point and centre count."""
    side = [np.cos(np.pi / 4), np.sin(np.pi / 4), 0.0, 0.0]  # 90 degrees about x
    for face, (turn, lift) in {"over": ([0.0, 1.0, 0.0, 0.0], 0.04), "side": (side, 0.02)}.items():
        world = _settled(ObjectSpec("die", "dice", (0.3, 0.2)),
                         ObjectSpec("stand", "object_stand", (0.55, 0.0)))
        center, _, _, _ = placement_frame(world, "stand", None)
        _posed(world, "die", [0.55, 0.0, center[2] - world.table_top() + lift + 0.001, *turn])
        world.forward()
        world.settle(0.8)
        up = abs(world.object_mat("die")[2, 2])
        assert up > 0.9 if face == "over" else up < 0.1
        assert _value(world, "on", "die", "stand"), face


def test_released_is_false_while_the_hand_holds_the_object() -> None:
    world = _settled(ObjectSpec("block", "block", (0.55, 0.0)))
    skills = Skills(world)
    skills.do("grasp", obj="block")
    skills.do("lift")
    assert not _value(world, "released", "block") and _value(world, "lifted", "block")
    skills.do("open_gripper")
    skills.player.wait(0.5)
    assert _value(world, "released", "block")


def test_left_and_right_need_the_margin_and_are_exclusive() -> None:
    world = _settled(ObjectSpec("a", "block", (0.5, 0.12)), ObjectSpec("b", "block", (0.5, -0.12)),
                     ObjectSpec("c", "block", (0.62, 0.14)))
    assert _value(world, "left_of", "a", "b") and not _value(world, "right_of", "a", "b")
    assert _value(world, "right_of", "b", "a") and not _value(world, "left_of", "b", "a")
    # c is 2 cm left of a: within the 3 cm margin neither holds
    assert not _value(world, "left_of", "c", "a") and not _value(world, "right_of", "c", "a")
    assert not _value(world, "left_of", "a", "c") and not _value(world, "right_of", "a", "c")


def test_near_is_false_beyond_ten_centimetres() -> None:
    world = _settled(ObjectSpec("a", "block", (0.5, 0.0)), ObjectSpec("b", "block", (0.5, 0.09)),
                     ObjectSpec("c", "block", (0.5, -0.115)))
    assert _value(world, "near", "a", "b") and _value(world, "near", "b", "a")
    assert not _value(world, "near", "a", "c") and not _value(world, "near", "b", "c")


def test_a_drawer_is_open_from_its_travel_on_shut_within_a_centimetre_and_a_bell_has_neither() -> None:
    world = _settled(ObjectSpec("cab", "cabinet", (0.68, 0.0)), ObjectSpec("bell", "bell", (0.5, 0.2)))
    skills = Skills(world)
    assert (_value(world, "opened", "cab"), _value(world, "closed", "cab")) == (False, True)
    states = {}
    for out in (0.05, 0.12):  # short of the 8 cm that count as open, then the skill's full pull
        skills.do("open_drawer", obj="cab", distance=out)
        states[out] = (_value(world, "opened", "cab"), _value(world, "closed", "cab"))
    assert states == {0.05: (False, False), 0.12: (True, False)}
    skills.do("close_drawer", obj="cab")
    assert (_value(world, "opened", "cab"), _value(world, "closed", "cab")) == (False, True)
    assert not _value(world, "opened", "bell") and not _value(world, "closed", "bell")


def test_what_lies_in_an_open_drawer_is_inside_it_and_comes_back_in_with_it() -> None:
    world = _settled(ObjectSpec("cab", "cabinet", (0.68, 0.0)), ObjectSpec("soap", "soap", (0.5, 0.2)))
    skills = Skills(world)
    skills.do("pick_and_place", obj="soap", target="cab")  # into the shut drawer: lands on the cabinet
    assert not _value(world, "inside", "soap", "cab")
    world = _settled(ObjectSpec("cab", "cabinet", (0.68, 0.0)), ObjectSpec("soap", "soap", (0.5, 0.2)))
    skills = Skills(world)
    skills.do("open_drawer", obj="cab")
    skills.do("pick_and_place", obj="soap", target="cab")  # the region came out with the drawer
    assert _value(world, "inside", "soap", "cab")
    skills.do("close_drawer", obj="cab")
    assert _value(world, "inside", "soap", "cab") and _value(world, "closed", "cab")


def test_a_mug_lying_on_its_side_on_a_racks_base_does_not_hang_from_it() -> None:
    """It touches the rack and its origin (the centre of its base) stands 5 cm up, as a hanging mug's
    does; its lowest point lies on the rack's base plate. Hung by the skill, it hangs."""
    from vcage.tasks import predicates as P

    world = _composed(ObjectSpec("rack", "mug_rack", (0.6, 0.1)), ObjectSpec("mug", "mug", (0.45, -0.15)))
    adr = int(world.model.jnt_qposadr[world.model.joint("mug/free").id])
    side = [np.cos(np.pi / 4), 0.0, np.sin(np.pi / 4), 0.0]  # its axis along +x: lying on its side
    world.data.qpos[adr:adr + 7] = [0.56, 0.07, world.table_top() + 0.012 + 0.042, *side]
    world.forward()
    world.settle(0.5)
    assert P.contact_between(world, "mug", "rack") and P.lifted(world, "mug")
    assert not _value(world, "hanging", "mug", "rack")
    world = _settled(ObjectSpec("mug", "mug", (0.45, -0.12)), ObjectSpec("rack", "mug_rack", (0.63, 0.08)))
    Skills(world).do("hang", obj="mug", target="rack")
    world.settle(0.5)
    assert _value(world, "hanging", "mug", "rack")


def test_on_needs_the_object_to_touch_its_target() -> None:
    """A cup standing in a basket that rests on a coaster is over the coaster and a few millimetres
    above its top, yet rests on the basket (seen in Vanilla rollouts, whose scenes put the coaster
    under the basket); a cup standing on the coaster is on it."""
    world = _settled(ObjectSpec("coaster", "coaster", (0.55, 0.0)),
                     ObjectSpec("basket", "basket", (0.55, 0.0), z=0.7625),
                     ObjectSpec("cup", "cup", (0.55, 0.0), z=0.775))
    center, _, _, _ = placement_frame(world, "coaster", None)
    assert abs(world.object_pos("cup")[2] - center[2]) < 0.02  # as low as resting on it ...
    assert not _value(world, "on", "cup", "coaster")  # ... but held up by the basket
    alone = _settled(ObjectSpec("coaster", "coaster", (0.55, 0.0)),
                     ObjectSpec("cup", "cup", (0.55, 0.0), z=0.77))
    assert _value(alone, "on", "cup", "coaster")
