"""The image critic on real renders: it sees pixels and masks only, and says why it rejects."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from vcage.critics.base import Observation, View
from vcage.critics.image import ImageCritic
from vcage.critics.image.thresholds import DEFAULT
from vcage.critics.masks import best_move, inward, moved
from vcage.planning.goals import put_at, put_on
from vcage.planning.schema import Predicate, Subtask
from vcage.scene.compose import compose
from vcage.scene.spec import ObjectSpec, SceneSpec
from vcage.sim.render import Renderer
from vcage.sim.world import World
from vcage.tasks.oracle import Oracle
from vcage.tasks.verifier import render_views

CRITIC = ImageCritic()
PAD = ObjectSpec("pad", "mouse_pad", (0.58, 0.1))


def _views(world: World) -> dict[str, View]:
    with Renderer(world, 320, 240) as r:
        return render_views(r)


def _world(*objects: ObjectSpec) -> World:
    world = compose(SceneSpec(objects=objects)).make_world()
    world.settle(0.3)
    return world


def _judge(before: World, after: World, subtask):  # type: ignore[no-untyped-def]
    obs = Observation(subtask=subtask, labels=tuple(after.object_names), before=_views(before),
                      after=_views(after))
    return CRITIC.judge(obs), Oracle().check(after, subtask.predicates)


def _judge_typed(before: World, after: World, subtask: Subtask) -> tuple[bool, str, dict[str, bool]]:
    """The critic's verdict (with the plan's types, as in a run) and the oracle's."""
    types = {n: after.object(n).type_name for n in after.object_names}
    obs = Observation(subtask=subtask, labels=tuple(after.object_names), before=_views(before),
                      after=_views(after), types=types)
    verdict = CRITIC.judge(obs)
    return verdict.accept, verdict.reason, Oracle().check(after, subtask.predicates)


def test_object_on_its_target_is_accepted_like_the_oracle() -> None:
    start = _world(ObjectSpec("block", "block", (0.5, -0.15)), PAD)
    done = _world(ObjectSpec("block", "block", (0.58, 0.1), z=0.756), PAD)
    verdict, oracle = _judge(start, done, put_on("block", "pad", "the block is on the pad"))
    assert verdict.accept, verdict.reason
    assert all(oracle.values())


def test_object_beside_its_target_is_rejected_with_the_reason() -> None:
    start = _world(ObjectSpec("block", "block", (0.5, -0.15)), PAD)
    missed = _world(ObjectSpec("block", "block", (0.58, -0.05)), PAD)
    verdict, oracle = _judge(start, missed, put_on("block", "pad", "the block is on the pad"))
    assert not verdict.accept and "overlaps pad from the top" in verdict.reason
    assert not oracle["on(block, pad)"]


def test_left_right_order_from_the_top_view() -> None:
    world = _world(ObjectSpec("a", "block", (0.55, 0.15)), ObjectSpec("b", "block", (0.55, -0.15)))
    sub = put_at("a", (0.55, 0.15), "a is left of b", left_of="b")
    verdict, oracle = _judge(world, world, sub)
    assert verdict.accept and oracle["left_of(a, b)"]
    swapped = put_at("b", (0.55, -0.15), "b is left of a", left_of="a")
    verdict, _ = _judge(world, world, swapped)
    assert not verdict.accept and "column difference" in verdict.reason


@pytest.mark.parametrize("missing", ["top", "front"])
def test_missing_views_reject_instead_of_guessing(missing: str) -> None:
    world = _world(ObjectSpec("block", "block", (0.58, 0.1), z=0.756), PAD)
    views = _views(world)
    del views[missing]
    obs = Observation(subtask=put_on("block", "pad", "block on pad"), labels=tuple(world.object_names),
                      before=views, after=views)
    assert not CRITIC.judge(obs).accept
    assert np.all(views[next(iter(views))].segmentation >= -2)


def _subtask(*preds: tuple[str, tuple[str, ...]]) -> Subtask:
    return Subtask(skill="retreat", description="a check of one predicate",
                   predicates=tuple(Predicate(name=n, args=a) for n, a in preds))


def test_near_is_measured_in_metres_from_the_orthographic_top_view() -> None:
    close = _world(ObjectSpec("a", "block", (0.55, 0.0)), ObjectSpec("b", "block", (0.55, 0.07)))
    verdict, oracle = _judge(close, close, _subtask(("near", ("a", "b"))))
    assert verdict.accept and oracle["near(a, b)"], verdict.reason
    far = _world(ObjectSpec("a", "block", (0.55, 0.0)), ObjectSpec("b", "block", (0.55, 0.2)))
    verdict, oracle = _judge(far, far, _subtask(("near", ("a", "b"))))
    assert not verdict.accept and not oracle["near(a, b)"] and "20 cm apart" in verdict.reason


def test_lifted_needs_the_object_to_rise_in_the_front_view() -> None:
    resting = _world(ObjectSpec("block", "block", (0.55, 0.0)))
    held_up = compose(SceneSpec(objects=(ObjectSpec("block", "block", (0.55, 0.0), z=0.85),))).make_world()
    held_up.forward()  # not settled: the block hangs where a hand would hold it
    verdict, oracle = _judge(resting, held_up, _subtask(("lifted", ("block",))))
    assert verdict.accept and oracle["lifted(block)"], verdict.reason
    verdict, oracle = _judge(resting, resting, _subtask(("lifted", ("block",))))
    assert not verdict.accept and not oracle["lifted(block)"] and "rose by 0 px" in verdict.reason


def test_an_object_that_already_stood_tipped_is_not_upright() -> None:
    """A bell lying on its side before and after the subtask: its outline and height did not change,
    so only its height against its type's tells (a standing bell is at most 6.3 cm tall). A bell
    standing is accepted, and so is one standing on a block (what stands under it raises it)."""
    def judge(before: World, after: World) -> tuple[bool, str, bool]:
        accept, reason, oracle = _judge_typed(before, after, _subtask(("upright", ("bell",))))
        return accept, reason, oracle["upright(bell)"]

    lying = compose(SceneSpec(objects=(ObjectSpec("bell", "bell", (0.55, 0.05), z=0.8),))).make_world()
    adr = int(lying.model.jnt_qposadr[lying.model.joint("bell/free").id])
    lying.data.qpos[adr + 3:adr + 7] = [np.cos(np.pi / 4), np.sin(np.pi / 4), 0.0, 0.0]  # on its side
    lying.forward()
    lying.settle(0.8)
    accept, reason, upright = judge(lying, lying)
    assert not upright and not accept and "higher than bell standing reaches" in reason, reason
    standing = _world(ObjectSpec("bell", "bell", (0.55, 0.05)))
    accept, reason, upright = judge(standing, standing)
    assert upright and accept, reason
    block = ObjectSpec("block", "block", (0.55, 0.05))
    before = _world(block, ObjectSpec("bell", "bell", (0.45, -0.15)))
    on_block = _world(block, ObjectSpec("bell", "bell", (0.55, 0.05), z=0.8))
    accept, reason, upright = judge(before, on_block)
    assert upright and accept, reason


def test_a_mouse_on_a_phone_lying_on_the_pad_is_not_on_the_pad() -> None:
    """Vanilla left phones lying flat on the pad, and put the mouse on one: held up by the phone
    (1.1 cm) over most of its outline, it does not touch the pad (the oracle: not on it), though
    its top stands no higher than the thin pad's tolerance allows. Beside the phone it is on the pad."""
    pad = ObjectSpec("pad", "mouse_pad", (0.55, 0.1))
    phone = ObjectSpec("phone", "phone", (0.55, 0.1), yaw=np.pi / 2, z=0.757)
    sub = put_on("mouse", "pad", "the mouse is on the pad")
    before = _world(ObjectSpec("mouse", "mouse", (0.45, -0.15)), pad, phone)
    on_phone = _world(ObjectSpec("mouse", "mouse", (0.55, 0.1), z=0.77), pad, phone)
    accept, reason, oracle = _judge_typed(before, on_phone, sub)
    assert not oracle["on(mouse, pad)"]
    assert not accept and "mouse lies over phone" in reason, reason
    moved = ObjectSpec("phone", "phone", (0.55, 0.155), yaw=np.pi / 2, z=0.757)
    beside = _world(ObjectSpec("mouse", "mouse", (0.55, 0.07), z=0.76), pad, moved)
    accept, reason, oracle = _judge_typed(_world(ObjectSpec("mouse", "mouse", (0.45, -0.15)), pad, moved),
                                          beside, sub)
    assert oracle["on(mouse, pad)"] and accept, reason


def test_a_seal_on_a_coaster_lying_on_the_mat_is_not_on_the_mat() -> None:
    """A coaster (5 mm, pressed 0.6 mm into the ink) lying on the stamp mat holds a seal put on it
    off the mat: the oracle says not on it. Under the seal's whole outline, the coaster's top 4 mm
    above the mat's surface says so (Vanilla left seals standing on a phone whose top was 3.3 mm
    above the mat). Put on the mat beside the coaster, the seal is on it."""
    mat = ObjectSpec("mat", "stamp_mat", (0.55, 0.1))
    sub = put_on("seal", "mat", "the seal is on the mat")
    away = ObjectSpec("seal", "seal", (0.45, -0.15))
    for coaster, seal, on in ((ObjectSpec("coaster", "coaster", (0.55, 0.1), z=0.757),
                               ObjectSpec("seal", "seal", (0.55, 0.1), z=0.763), False),
                              (ObjectSpec("coaster", "coaster", (0.55, 0.24)),
                               ObjectSpec("seal", "seal", (0.55, 0.09), z=0.757), True)):
        accept, reason, oracle = _judge_typed(_world(away, mat, coaster), _world(seal, mat, coaster), sub)
        assert oracle["on(seal, mat)"] is on
        assert accept is on, reason
        assert on or "seal lies over coaster" in reason, reason


def test_a_block_put_beside_a_nudged_one_or_where_one_stood_is_on_the_table() -> None:
    """A block put down against another nudges it a centimetre, so the sliver of the other's outline
    before that the new block covers now is not the other block: it shows all of itself. A bottle
    that stood where the block is put and is gone now (knocked off the table) does not hold it up:
    the table shows where the bottle stood. The oracle counts the block on the table in both; the
    same block put on the other block is not."""
    sub = put_at("red", (0.55, 0.06), "the red block is on the table")
    away = ObjectSpec("red", "block", (0.45, -0.15))
    blue = ObjectSpec("blue", "block", (0.55, 0.1))
    nudged = ObjectSpec("blue", "block", (0.55, 0.11))
    accept, reason, oracle = _judge_typed(_world(away, blue), _world(ObjectSpec("red", "block", (0.55, 0.06)),
                                                                      nudged), sub)
    assert oracle["on_table(red)"] and accept, reason
    on_blue = _world(ObjectSpec("red", "block", (0.55, 0.1), z=0.8), blue)
    accept, reason, oracle = _judge_typed(_world(away, blue), on_blue, sub)
    assert not oracle["on_table(red)"] and not accept, reason
    bottle = ObjectSpec("bottle", "bottle", (0.55, 0.06))
    gone = ObjectSpec("bottle", "bottle", (1.6, 0.0), z=0.05)
    after = _world(ObjectSpec("red", "block", (0.55, 0.06)), gone)
    accept, reason, oracle = _judge_typed(_world(away, bottle), after, sub)
    assert oracle["on_table(red)"] and accept, reason


def test_a_cube_that_stood_tilted_and_lies_flat_now_is_not_turned_over() -> None:
    """A block rests on any face (the oracle's cube): one that leaned before the subtask, so that
    the top view showed two of its faces, and lies flat on its base block now shows a plane where
    it showed a bend, as a mouse turned onto its back does, but it is on the base."""
    base = ObjectSpec("base", "block", (0.55, 0.1))
    leaning = ObjectSpec("middle", "block", (0.45, -0.15), z=0.77)  # in the air: only the views count
    before = compose(SceneSpec(objects=(leaning, base))).make_world()
    adr = before.model.jnt_qposadr[before.model.body_jntadr[before.object("middle").body_id]]
    before.data.qpos[adr + 3:adr + 7] = (np.cos(0.15), np.sin(0.15), 0.0, 0.0)  # leaning 0.3 rad
    before.forward()
    after = _world(ObjectSpec("middle", "block", (0.55, 0.115), z=0.8), base)  # the base shows beside it
    accept, reason, oracle = _judge_typed(before, after, put_on("middle", "base", "the block is on the base"))
    assert oracle["on(middle, base)"] and accept, reason


def test_a_cup_standing_on_a_stand_over_its_coaster_is_not_on_it() -> None:
    """Seen from above, a cup shows its floor inside its rim: its top is the rim, at its outline.
    Standing on a stand over the coaster (one the top view did not show before, so nothing there
    says what holds the cup up), the cup's rim is a stand higher than a cup on the coaster reaches,
    though its floor (what the inside of its outline shows) is not (a Vanilla rollout left a cup on
    a basket turned over the coaster)."""
    coaster = ObjectSpec("coaster", "coaster", (0.55, 0.1))
    sub = put_on("cup", "coaster", "the cup is on the coaster")
    before = _world(ObjectSpec("cup", "cup", (0.45, -0.15)), coaster)
    stand = ObjectSpec("stand", "object_stand", (0.55, 0.1), z=0.756)
    on_stand = _world(ObjectSpec("cup", "cup", (0.55, 0.1), z=0.81), coaster, stand)
    accept, reason, oracle = _judge_typed(before, on_stand, sub)
    assert not oracle["on(cup, coaster)"]
    assert not accept and "higher than cup standing on coaster's surface reaches" in reason, reason


def test_a_phone_standing_on_its_edge_in_the_stand_is_not_on_it() -> None:
    """On the stand's ramp a phone lies tilted with it, its top its width times the ramp's sine
    above the slot; Vanilla left phones standing on an edge in the slot (the oracle: not on it),
    their tops several centimetres higher. Lying on the ramp, as the skill puts it, it is on it."""
    stand = ObjectSpec("stand", "phone_stand", (0.55, 0.1))
    sub = put_on("phone", "stand", "the phone is on its stand")
    before = _world(ObjectSpec("phone", "phone", (0.45, -0.15)), stand)

    def set_in_slot(turn: float) -> World:
        phone = ObjectSpec("phone", "phone", (0.57, 0.1), z=0.84)
        world = compose(SceneSpec(objects=(phone, stand))).make_world()
        adr = int(world.model.jnt_qposadr[world.model.joint("phone/free").id])
        world.data.qpos[adr + 3:adr + 7] = [np.cos(turn / 2), np.sin(turn / 2), 0.0, 0.0]  # about its x axis
        world.forward()
        world.settle(0.8)
        return world

    accept, reason, oracle = _judge_typed(before, set_in_slot(1.5), sub)  # on its long edge
    assert not oracle["on(phone, stand)"]
    assert not accept and "higher than phone standing on stand's surface reaches" in reason, reason
    accept, reason, oracle = _judge_typed(before, set_in_slot(0.35), sub)  # down on the ramp
    assert oracle["on(phone, stand)"] and accept, reason


def test_an_outline_is_followed_through_a_turn_as_well_as_a_slide() -> None:
    """``best_move`` finds the turn (of those it is given) and the translation that lay a mask over
    its turned and moved self, which a translation alone cannot."""
    before = np.zeros((120, 160), dtype=bool)
    before[40:60, 30:70] = True  # 20 by 40 pixels
    rows, cols = np.nonzero(before)
    now = moved(before, (24.0, float(rows.mean()), float(cols.mean()), 30, 50))
    move = best_move(before, now, DEFAULT.TURNS)
    assert move[0] == 24.0 and move[3:] == (30, 50)
    assert (moved(before, move) == now).all()
    slid = best_move(before, now, (0.0,))
    assert (moved(before, slid) & ~now).sum() > 40  # the corners a slide leaves overhanging


def test_inward_measures_a_centre_from_the_outline_of_a_region() -> None:
    """``inward``: how far the centre of a mask lies in from a region's hull, in pixels (minus how far
    out, outside it)."""
    region = np.zeros((100, 100), dtype=bool)
    region[20:80, 10:90] = True
    blob = np.zeros_like(region)
    blob[28:33, 40:45] = True  # centre (30, 42): 10 rows below the region's top edge
    assert inward(blob, region) == pytest.approx(11.0, abs=1.0)
    outside = np.zeros_like(region)
    outside[8:13, 40:45] = True  # centre (10, 42): 10 rows above it
    assert inward(outside, region) == pytest.approx(-10.0, abs=1.0)


def test_the_critics_version_changes_with_any_rule_and_its_thresholds_are_recorded(tmp_path: Path) -> None:
    from vcage.critics import image
    from vcage.critics.image import thresholds

    files = image.rule_files()
    package = {p.name for p in Path(image.__file__).parent.glob("*.py")}
    assert package <= {p.name for p in files} and "masks.py" in {p.name for p in files}
    assert ImageCritic().version() == f"image@{image.rules_digest()}"
    changed = tmp_path / "thresholds.py"
    source = Path(thresholds.__file__).read_text()
    changed.write_text(source.replace("NEAR: float = 0.1 ", "NEAR: float = 0.12 "))
    assert changed.read_text() != Path(thresholds.__file__).read_text()
    swapped = [changed if p.name == "thresholds.py" else p for p in files]
    assert image.rules_digest(swapped) != image.rules_digest()
    rules = ImageCritic().rules()
    default = thresholds.DEFAULT
    assert rules["NEAR"] == default.NEAR and rules["BUTTON_PX"] == list(default.BUTTON_PX)
    assert json.loads(json.dumps(rules)) == rules  # stored as JSON in the runs log
