"""The image critic on real failed rollouts: faults injected into the skills, executed in MuJoCo.

Every image check has a case here where the oracle says its predicate failed after a rollout with
an injected fault (nothing teleported), and the check itself must say so: replacing any check of
``IMAGE_CHECKS`` with "accept" fails a test. The same scenes run as planned must be accepted, so a
critic that rejects everything fails too.

The rollouts are read from ``tests/critics/observations/`` (what the critic was shown, with the
oracle's values beside it): ``recipes.py`` says how each was made and makes it again, and
``tests/regenerate/`` checks that they still come out so under the locked versions. A new release
of the simulator moves chaotic rollouts; it cannot move these tests.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from critics.recipes import FAILURES, SCENARIOS, faulted, observed, planned, vanilla
from vcage.critics.base import Verdict
from vcage.critics.image import ImageCritic
from vcage.critics.image.measure import _peak
from vcage.critics.image.thresholds import ROBOT
from vcage.critics.masks import touch

CRITIC = ImageCritic()


def _judged_vanilla(goal: str, episode: int, index: int, oracle: dict[str, bool]) -> Verdict:
    """The critic's verdict on subtask ``index`` of Vanilla's episode ``episode`` of ``goal``, once the
    oracle's values there are checked to be ``oracle`` (the state the test describes)."""
    case = observed(vanilla(goal, episode, index))
    assert case.oracle == oracle
    return CRITIC.judge(case.obs)


def _placed(name: str) -> tuple[bool, Verdict]:
    """The oracle's and the critic's verdicts on a subtask done as planned whose views after (and some
    before) were replaced by the scene with the placed object dropped in a given pose and settled
    (``recipes._set_down``): whether the oracle counts its placing predicates true, and the verdict."""
    case = observed(name)
    return case.success, CRITIC.judge(case.obs)


@pytest.mark.parametrize("scenario", sorted(SCENARIOS))
def test_the_scene_done_as_planned_is_accepted(scenario: str) -> None:
    case = observed(planned(scenario))
    verdict = CRITIC.judge(case.obs)
    assert case.success, case.oracle
    assert verdict.accept, verdict.reason


@pytest.mark.parametrize(("scenario", "fault", "seed", "predicate"), FAILURES,
                         ids=[f"{f}-{p}" for _, f, _, p in FAILURES])
def test_an_injected_silent_failure_is_rejected_by_its_check(scenario: str, fault: str, seed: int,
                                                             predicate: str) -> None:
    case = observed(faulted(scenario, fault, seed))
    assert case.extra["applied"]
    assert case.oracle[predicate] is False, case.oracle  # a real failure
    verdict = CRITIC.judge(case.obs)
    assert not verdict.accept
    assert verdict.details["checks"][predicate] is False, verdict.reason
    assert predicate in verdict.reason


def test_an_object_put_down_on_clutter_that_lies_on_its_target_is_not_on_it() -> None:
    """A block lies on the pad; the mouse put on the pad comes to rest on the block. From the top the
    mouse lies over the pad as it would on it; what the top view showed before (the block, 4.5 cm
    high, where the mouse is now) says it cannot be down on the pad."""
    case = observed("mouse-onto-a-block-on-the-pad")
    assert case.oracle == {"on(mouse, pad)": False, "released(mouse)": True}
    verdict = CRITIC.judge(case.obs)
    assert not verdict.accept
    assert "mouse lies over block" in verdict.reason


def test_a_mouse_on_its_back_on_the_pad_is_not_on_it() -> None:
    """Vanilla rollouts left mice on their backs on the pad (the oracle: not on it; its outline from
    the top is the same). The mouse's domed top was far from a plane; its flat underside is not."""
    oracle, verdict = _placed("mouse-on-its-back-on-the-pad")  # half a turn about x
    assert not oracle
    assert not verdict.accept and "turned over" in verdict.reason, verdict.reason


def test_a_mouse_that_lay_on_its_back_before_and_lies_so_on_the_pad_is_not_on_it() -> None:
    """Vanilla left mice on their backs before their subtask too, and carried them so onto the pad:
    compared with itself before, the top kept its (flat) shape. The mouse's type declares its dome,
    and the flat underside lies far closer to a plane than the dome does."""
    oracle, verdict = _placed("mouse-on-its-back-before-and-on-the-pad")
    assert not oracle
    assert not verdict.accept and "top is flat" in verdict.reason, verdict.reason


def test_a_mouse_tipped_over_at_a_slant_on_the_pad_is_not_on_it() -> None:
    """A Vanilla rollout left a mouse on the pad tilted 2.5 rad (this orientation): most of its flat
    underside up, part of its dome showing, so its top lies far enough from a plane (0.46 of its
    relief before) to pass the comparison with itself before; but under half as far as the dome its
    type declares (2.6 mm, where a mouse standing shows 5.4 mm at its smallest scale)."""
    oracle, verdict = _placed("mouse-tipped-at-a-slant-on-the-pad")
    assert not oracle
    assert not verdict.accept and "top is flat (2.6 mm from a plane" in verdict.reason, verdict.reason


@pytest.mark.parametrize(("goal", "episode", "index"), [
    ("tidy_the_desk", 880, 1),
    ("get_ready_for_work", 852, 2),
])
def test_a_mouse_turned_over_at_a_slant_whose_dome_still_bends_is_not_on_the_pad(goal: str, episode: int,
                                                                                 index: int) -> None:
    """Vanilla rollouts left mice turned over at a slant on the pad (2.4 rad) whose tops showed enough
    of the dome to bend as a dome does and to lie far from a plane: only the plane's slope tells, 0.7
    where a mouse standing on the level pad slopes at most 0.45."""
    verdict = _judged_vanilla(goal, episode, index, {"on(mouse, pad)": False, "released(mouse)": True})
    assert verdict.details["checks"] == {"on(mouse, pad)": False, "released(mouse)": True}
    assert "it lies tipped over at a slant" in verdict.reason, verdict.reason


def test_a_mouse_leaning_a_little_on_the_pad_is_on_it() -> None:
    """A Vanilla rollout left the mouse on the pad a little tilted (its top's plane slopes 0.3): the
    oracle counts it on the pad, and so does the critic."""
    verdict = _judged_vanilla("tidy_the_desk", 871, 1, {"on(mouse, pad)": True, "released(mouse)": True})
    assert verdict.accept, verdict.reason



def test_a_mouse_on_the_pad_whose_dome_bends_less_than_before_is_on_it() -> None:
    """A Vanilla rollout carried a mouse fused with its neighbours onto the pad, where it stands on its
    base (the oracle: on it), its top read bending 0.54 as much as before from the top: how much a top
    bends says nothing of a turn that its plane's slope and relief do not."""
    verdict = _judged_vanilla("tidy_the_desk", 988, 1, {"on(mouse, pad)": True, "released(mouse)": True})
    assert verdict.accept, verdict.reason

def test_a_mouse_standing_on_its_end_on_the_pad_is_not_on_it() -> None:
    """Vanilla rollouts left mice standing on an end or propped on clutter on the pad: from the top
    they lie over it, their lowest point is down on it and their top is no flatter than before. Stood
    on its end, its top stands 5 cm higher than a mouse put down on the pad reaches."""
    oracle, verdict = _placed("mouse-on-its-end-on-the-pad")  # a quarter turn about y
    assert not oracle
    assert not verdict.accept and "higher than mouse standing on pad's surface reaches" in verdict.reason, \
        verdict.reason


def test_a_cup_lying_on_its_side_across_the_coaster_is_not_on_it() -> None:
    """Vanilla rollouts left cups lying on their sides across the coaster (the oracle: not on it, the
    base's centre 4 cm up): from the top most of the cup lies over the coaster, its lowest point is
    down on it, and it is round either way up. Its top, 7 cm above the coaster where it stood 9 cm
    tall, is nearer lying than standing."""
    oracle, verdict = _placed("cup-on-its-side-across-the-coaster")  # a quarter turn about x
    assert not oracle
    assert not verdict.accept and "lies on its side" in verdict.reason, verdict.reason


def test_a_cup_lying_on_its_side_over_a_coaster_it_hides_is_not_on_it() -> None:
    """Where the cup hides most of a coaster that moved (knocked as the cup fell), the top view cannot
    say where the coaster is, and the front view decides whether the cup rests on it; lying on its
    side, it is not on it all the same."""
    oracle, verdict = _placed("cup-on-its-side-over-a-coaster-it-hides")
    assert not oracle
    assert not verdict.accept and "lies on its side" in verdict.reason, verdict.reason


@pytest.mark.parametrize("episode", [816, 958])
def test_a_cup_that_never_stood_on_the_table_lying_on_its_side_is_not_on_the_coaster(episode: int) -> None:
    """Vanilla's naive placement fused these cups into the basket, so no view saw them stand on the
    table and their height says nothing of their scale; carried out, they came to lie on their sides
    on the coaster (the oracle: not on it). From the top they show their outer wall, not their inside:
    their top falls 1.5 cm to their lowest, where lying on its side a cup's falls at most its radius."""
    verdict = _judged_vanilla("set_the_table", episode, 0, {"on(cup, coaster)": False, "released(cup)": True})
    assert verdict.details["checks"] == {"on(cup, coaster)": False, "released(cup)": True}
    assert "cup shows no inside from the top" in verdict.reason, verdict.reason


def test_a_cup_tilted_on_the_coaster_showing_its_inside_is_on_it() -> None:
    """A Vanilla rollout left the cup leaning on the coaster against the basket it started fused with
    (the oracle: on it, the base's centre over the coaster). From the top its inside still shows, its
    top falling 6 cm to its lowest: it does not lie on its side."""
    verdict = _judged_vanilla("set_the_table", 945, 0, {"on(cup, coaster)": True, "released(cup)": True})
    assert verdict.accept, verdict.reason



def test_a_cup_whose_height_reads_lying_but_that_shows_its_inside_is_on_the_coaster() -> None:
    """A Vanilla rollout left the cup standing on the coaster tilted (the oracle: on it), its top
    8.1 cm above the coaster where it stood 9.8 cm tall and would lie 7.6 cm high: nearer lying than
    standing. From the top its inside shows (its top falls 7.6 cm to its lowest; lying on its side,
    at most its radius, 3.9 cm): it does not lie on its side."""
    verdict = _judged_vanilla("set_the_table", 830, 0, {"on(cup, coaster)": True, "released(cup)": True})
    assert verdict.accept, verdict.reason

def test_a_cup_standing_on_the_coaster_is_on_it_whatever_its_scale() -> None:
    """The side check reads the cup's scale from its height before: a small cup standing on the
    coaster is not taken for a large one lying down."""
    oracle, verdict = _placed("small-cup-standing-on-the-coaster")
    assert oracle
    assert verdict.accept, verdict.reason


def test_a_cup_moved_onto_the_middle_of_a_coaster_it_half_hid_is_on_it() -> None:
    """A Vanilla rollout began with the cup standing off-centre on the coaster and ended with it in
    the middle: the coaster's middle was hidden before and after, so its outline is a ring with
    fewer pixels than the cup. The overlap is asked of the region smaller by its hull (the cup)."""
    done = observed("cup-moved-to-the-middle-of-a-coaster-it-half-hid")
    assert done.success
    verdict = CRITIC.judge(done.obs)
    assert verdict.accept, verdict.reason


def test_a_cup_put_on_the_coaster_beside_a_basket_pushed_and_turned_is_on_it() -> None:
    """A Vanilla rollout dragged the basket along with the cup and turned it 16 degrees. Followed by a
    translation only, the basket's outline before overhangs it at two corners, one of them under the
    cup standing on the coaster beside it, which then seemed to lie over the basket's wall (6 cm
    high). Followed turned as well, the basket lies beside the cup."""
    oracle, verdict = _placed("cup-on-the-coaster-beside-a-turned-basket")
    assert oracle
    assert verdict.accept, verdict.reason


def test_a_seal_that_lay_on_its_side_before_and_lies_so_on_the_mat_is_not_on_it() -> None:
    """Vanilla rollouts (tidy the desk) left seals lying on their sides on the mat that lay so on the
    table before the subtask already (the oracle: not on it, the base's centre 2.7 cm up): their
    height before gives no scale, and their top shows no flat face it did not show before. A seal's
    top, 4.8 cm above the mat there, is nearer its longest side across at any scale (5.5 cm) than the
    least it stands on its base (9.6 cm)."""
    oracle, verdict = _placed("seal-on-its-side-before-and-on-the-mat")  # 1.78 rad about x, as they lay
    assert not oracle
    assert not verdict.accept and "lies on its side" in verdict.reason, verdict.reason


def test_a_loaf_upside_down_in_the_basket_is_inside_it() -> None:
    """A Vanilla rollout left a loaf standing on its end in the basket: inside it for the oracle, but
    its top, a flat end where the crust had been curved, was read as turned over. On a surface that
    means it does not rest on its base; in a container an object may lie any way up. Upside down,
    its flat underside shows from the top."""
    oracle, verdict = _placed("loaf-upside-down-in-the-basket")
    assert oracle
    assert verdict.accept, verdict.reason


def test_a_loaf_standing_on_end_in_the_basket_is_inside_it() -> None:
    """A Vanilla rollout left a loaf (at a large scale, in a small basket) standing on its end in the
    basket. Its top stood higher above the rim than the loaf lying down is tall; in a container its
    longest side bounds that, once its top view shows it turned."""
    oracle, verdict = _placed("loaf-on-its-end-in-the-basket")  # long axis up
    assert oracle
    assert verdict.accept, verdict.reason


@pytest.mark.parametrize("which", ["underside", "top"])  # scale 1.1 tilted 0.8 rad; 0.9 tilted 0.6
def test_a_loaf_leaning_from_the_floor_against_the_rim_is_inside_the_basket(which: str) -> None:
    """Vanilla rollouts left loaves leaning in the basket, one end on the floor and the other against
    the rim (inside for the oracle: the lowest point on the floor, the centre within the walls). The
    critic read such a loaf as lying level: its underside its own height under its highest point, at
    the rim (the large loaf), or its top no higher than its height above the rim (the small one). Its
    sloping top says it leans: its underside is judged under the top's lower end, and its longest
    side bounds its top."""
    oracle, verdict = _placed(f"loaf-leaning-against-the-rim-{which}")  # about y, its low end away
    assert oracle
    assert verdict.accept, verdict.reason


def test_a_loaf_leaning_on_a_cup_that_stands_in_the_basket_is_inside_it() -> None:
    """Vanilla composed scenes with a cup standing in the basket, taller than its walls; loaves put in
    came to rest leaning on the cup, their lower end on the floor (inside for the oracle). From the
    top a loaf lies over the cup, whose top stood above the rim, which says that a loaf lying level
    rests on it; a leaning one may rest against it, and its lower end decides."""
    oracle, verdict = _placed("loaf-leaning-on-a-cup-in-the-basket")  # its raised end towards the cup
    assert oracle
    assert verdict.accept, verdict.reason


def test_a_loaf_lying_on_a_cup_above_the_rim_is_not_inside_the_basket() -> None:
    """A Vanilla rollout left a loaf lying flat on a cup that stood in the basket, all of it above the
    rim. It lies as it did on the table, so its underside is its own height under its top: above
    the rim (and its height, not its longest side, bounds its top)."""
    oracle, verdict = _placed("loaf-lying-on-a-cup-above-the-rim")  # the cup on the basket's floor
    assert not oracle
    assert not verdict.accept and "above basket's rim" in verdict.reason, verdict.reason


def test_a_loaf_bridging_the_baskets_rims_is_not_inside_it() -> None:
    """A large loaf put across a small basket can come to rest on both long rims: from the top it lies
    over the basket, no higher than a loaf in a basket may reach, but its underside is at the rim's
    height (the oracle: not inside). Injected faults left five such loaves in the balanced set."""
    oracle, verdict = _placed("loaf-bridging-the-rims")  # its long side along the basket's short one
    assert not oracle
    assert not verdict.accept, "a loaf on the rims was accepted"
    assert "cm under basket's rim: it rests on the rim" in verdict.reason, verdict.reason


@pytest.mark.parametrize(("goal", "episode", "index", "why"), [
    ("set_the_table", 912, 1, "bread's centre lies 2.4 cm in from basket's outline"),
    ("prepare_breakfast", 858, 0, "the centre of bread's lower end lies 0.7 cm outside"),
], ids=["level", "leaning"])
def test_a_loaf_carried_across_the_baskets_wall_is_not_inside_it(goal: str, episode: int, index: int,
                                                                  why: str) -> None:
    """Vanilla's naive placement sinks loaves 2-3 cm into the basket's wall, and a fused pair moves as
    one. Put in, these came to rest across the wall (the oracle: not inside): one lying level with
    its centre 2.4 cm in from the basket's outline, where a loaf within the walls keeps half its
    width (2.8 cm at its smallest scale) in; one leaning, its lower end outside the basket. Most of
    each lies over the basket from the top and no higher than the rim allows: every other check
    passed them."""
    verdict = _judged_vanilla(goal, episode, index, {"inside(bread, basket)": False, "released(bread)": True})
    assert verdict.details["checks"] == {"inside(bread, basket)": False, "released(bread)": True}
    assert why in verdict.reason and "across basket's wall" in verdict.reason, verdict.reason


@pytest.mark.parametrize(("goal", "episode", "off"), [
    ("build_a_tower", 883, "2.0 cm off"),
    ("set_the_table", 863, "1.4 cm off"),
])
def test_a_bell_left_leaning_where_it_was_fused_is_not_upright(goal: str, episode: int, off: str) -> None:
    """Vanilla's naive placement sinks the bell into a neighbour, and it stands tilted beyond the
    oracle's 0.2 rad before its press and after it: its outline and its height did not change, so
    only where its button lies over its base tells (the hand pressed it: the press itself passes)."""
    verdict = _judged_vanilla(goal, episode, 2, {"pressed(bell)": True, "upright(bell)": False})
    assert verdict.details["checks"] == {"pressed(bell)": True, "upright(bell)": False}
    assert f"bell's button lies {off} the centre of its base" in verdict.reason, verdict.reason


def test_a_bell_leaning_less_than_the_oracles_bound_is_upright() -> None:
    """A bell fused into a neighbour leans a little (its button 0.7 cm off its base's centre, under
    the 1.1 cm a tilt of 0.2 rad gives at its smallest scale): the oracle counts it upright, and so
    does the critic."""
    verdict = _judged_vanilla("prepare_breakfast", 902, 2, {"pressed(bell)": True, "upright(bell)": True})
    assert verdict.accept, verdict.reason


def test_a_loaf_lying_level_against_the_baskets_wall_is_inside_it() -> None:
    """Dropped over the wall, a loaf comes to rest on the floor against its inside: its centre lies
    as near the basket's outline as a loaf in the basket can (4.1 cm in), and it is inside."""
    oracle, verdict = _placed("loaf-level-against-the-wall-inside")
    assert oracle
    assert verdict.accept, verdict.reason


def test_a_block_set_diagonally_off_centre_on_a_block_is_on_it() -> None:
    """A block resting on another with its centre over the face but off it along both axes covers
    under half of it from the top (Vanilla towers the oracle counts stacked showed 41-57%). A cube's
    surface is its whole face, as large as the block on it, so the centre decides, not the overlap."""
    oracle, verdict = _placed("block-diagonally-off-centre-on-a-block")
    assert oracle
    assert verdict.accept, verdict.reason


def test_a_block_put_down_where_another_stands_is_not_on_the_table() -> None:
    """Put down at a spot another block of its size occupies, the block comes to rest on it: from the
    top it shows where it should, and its neighbour, no larger, mostly hides under it. The heights of
    the top view say it stands a block higher than the table allows."""
    result = observed("block-put-down-where-another-stands")
    assert result.oracle == {"on_table(a)": False, "released(a)": True}
    verdict = CRITIC.judge(result.obs)
    assert not verdict.accept and "higher than resting on the table allows" in verdict.reason, verdict.reason


def test_a_press_hidden_from_the_front_by_a_cup_is_judged_from_the_top() -> None:
    """A cup stands between the bell and the front camera: the fingers go down behind it, so the
    front view shows no contact. The top view's cover and depth say the press was full; a press
    beside the button, equally hidden, still fails the cover."""
    done = observed("bell-behind-a-cup")
    front = done.obs.during["front"]
    bell = front.segmentation == done.obs.labels.index("bell")
    assert done.success and not touch(front.segmentation == ROBOT, bell, front.depth)
    verdict = CRITIC.judge(done.obs)
    assert verdict.accept, verdict.reason
    blind = {m: {c: replace(v, depth=None) if c == "top" else v for c, v in getattr(done.obs, m).items()}
             for m in ("before", "during", "after")}
    verdict = CRITIC.judge(replace(done.obs, **blind))  # without the top view's depth: no evidence left
    assert not verdict.accept and "hides where the hand met bell" in verdict.reason, verdict.reason
    missed = observed("bell-behind-a-cup-press_miss-0")
    assert missed.oracle["pressed(bell)"] is False
    verdict = CRITIC.judge(missed.obs)
    assert not verdict.accept and "covered" in verdict.reason, verdict.reason


def test_a_press_on_a_bell_the_front_view_never_shows_is_judged_from_the_top() -> None:
    """A cereal box stands between the bell and the front camera and hides all of it, before and
    during the press (a Vanilla rollout hid a bell behind a basket so): the front view can tell
    nothing, the top view's cover and depth decide, and a hovering hand still fails them."""
    done = observed("bell-behind-a-box")
    bell = done.obs.labels.index("bell")
    fronts = (done.obs.before["front"], done.obs.during["front"])
    assert not any((v.segmentation == bell).any() for v in fronts)
    assert done.success
    verdict = CRITIC.judge(done.obs)
    assert verdict.accept, verdict.reason
    hover = observed("bell-behind-a-box-press_hover-0")
    assert hover.oracle["pressed(bell)"] is False
    verdict = CRITIC.judge(hover.obs)
    assert not verdict.accept and "short of pressing" in verdict.reason, verdict.reason


def test_a_press_on_a_bell_showing_a_sliver_beside_what_hides_it_is_judged_from_the_top() -> None:
    """A pen holder in front of the bell hides all of it from the front but a sliver at its edge (a
    Vanilla rollout): the hand goes down behind the holder, beside the sliver's columns. The bell
    reaches on behind the holder, so where the hand met it cannot be seen, and the top view judges:
    a full press passes, one beside the button or short of it does not."""
    done = observed("bell-behind-a-holder")
    front = done.obs.during["front"]
    assert 0 < (front.segmentation == done.obs.labels.index("bell")).sum() < 10  # a sliver shows
    assert done.success
    verdict = CRITIC.judge(done.obs)
    assert verdict.accept, verdict.reason
    for fault, why in (("press_miss", "covered"), ("press_light", "short of pressing")):
        failed = observed(f"bell-behind-a-holder-{fault}-0")
        assert failed.oracle["pressed(bell)"] is False
        verdict = CRITIC.judge(failed.obs)
        assert not verdict.accept and why in verdict.reason, verdict.reason


def test_a_lone_stray_depth_pixel_inside_the_bell_is_not_its_top() -> None:
    """One pixel inside a bell's outline in the top view read 59 cm above the table (a Vanilla rollout):
    taken as the bell's top, the press read half a metre past a full one, "the bell gave way". The
    top is the highest pixel that a neighbour inside comes near; a light press stays short."""
    done = observed(planned("pressed"))
    light = observed(faulted("pressed", "press_light", 0))
    assert done.success and not light.success
    for result, accept in ((done, True), (light, False)):
        top = result.obs.before["top"]
        assert top.depth is not None
        bell = top.segmentation == result.obs.labels.index("bell")
        rows, cols = np.nonzero(bell & ~np.roll(~bell, 2, 0) & ~np.roll(~bell, -2, 0)
                                & ~np.roll(~bell, 2, 1) & ~np.roll(~bell, -2, 1))
        depth = top.depth.copy()
        depth[rows[len(rows) // 2], cols[len(cols) // 2]] -= 0.5  # one pixel inside, half a metre up
        stray = replace(result.obs, before={**result.obs.before, "top": replace(top, depth=depth)})
        verdict = CRITIC.judge(stray)
        assert verdict.accept is accept, verdict.reason
        assert "gave way" not in verdict.reason, verdict.reason


def test_the_peak_keeps_a_one_pixel_ridge_and_drops_a_lone_spike() -> None:
    heights = np.zeros((9, 9))
    heights[4, 1:8] = 0.03  # a lever's ridge, one pixel wide
    mask = np.ones_like(heights, dtype=bool)
    assert _peak(heights, mask) == pytest.approx(0.03)
    heights[2, 2] = 0.5  # a stray reading above everything around it
    assert _peak(heights, mask) == pytest.approx(0.03)


def test_a_press_that_rocks_the_clock_is_refused() -> None:
    """A clock standing with one side on a marker rocks down onto it under the hand (as clocks on
    clutter did on Vanilla rollouts): the hand reads deeper than the button goes, though its cover
    and depth pass and the clock shows as before from the top. The oracle: not upright."""
    result = observed("clock-rocking-onto-a-marker")
    assert result.oracle == {"pressed(clock)": True, "upright(clock)": False}
    verdict = CRITIC.judge(result.obs)
    assert not verdict.accept and "gave way under it" in verdict.reason, verdict.reason


def test_a_press_is_judged_at_its_own_lowest_moment() -> None:
    """A sweep after the press (knocking nothing over here) takes the hand lower than the press did;
    the views "during" the subtask are still those of the press, which the critic accepts."""
    result = observed(faulted("pressed", "knock_over", 1))
    assert result.extra["applied"] and result.success, result.oracle
    verdict = CRITIC.judge(result.obs)
    assert verdict.accept, verdict.reason


def test_a_board_put_back_with_its_code_away_from_the_robot_does_not_face_it() -> None:
    """Picked up and put back unturned, the board's plate lies across the way to the robot, as when
    it faces it: only the front view (the code's contrast towards the front camera, opposite the
    robot) tells that it faces away."""
    result = observed("board-put-back-unturned")
    assert result.oracle["facing(board)"] is False and result.oracle["released(board)"]
    verdict = CRITIC.judge(result.obs)
    assert verdict.details["checks"] == {"facing(board)": False, "released(board)": True}, verdict.reason
    assert "faces away from the robot" in verdict.reason


def test_a_mug_hung_on_one_rack_does_not_hang_from_the_other() -> None:
    """High above the table, as hanging makes it, but on the wrong rack: it touches only that one."""
    result = observed("mug-hung-on-the-other-rack")
    assert result.oracle == {"hanging(mug, other)": False, "released(mug)": True}
    verdict = CRITIC.judge(result.obs)
    assert verdict.details["checks"]["hanging(mug, other)"] is False, verdict.reason
    assert "does not touch other" in verdict.reason


def test_the_checks_under_test_cover_every_image_check() -> None:
    from vcage.critics.image import IMAGE_CHECKS

    tested = {p.split("(")[0] for *_, p in FAILURES}
    assert tested == set(IMAGE_CHECKS.names())


def test_a_lone_pixel_at_the_outline_does_not_set_how_high_the_button_is() -> None:
    """A pixel's depth at a silhouette can be far off: one at 0.25 m above the table on the 9 cm
    clock made a light press look deep enough. The same light press, with such a pixel put on the
    clock's outline in the view before it, is still refused for stopping short."""
    from dataclasses import replace

    from vcage.critics.masks import dilate

    result = observed(faulted("upright", "press_light", 1))
    obs = result.obs
    view = obs.before["top"]
    clock = view.segmentation == obs.labels.index("clock")
    rows, cols = np.nonzero(clock & dilate(~clock, 1))  # the outline
    depth = view.depth.copy()
    depth[rows[0], cols[0]] = float(np.median(depth[view.segmentation == -1])) - 0.25
    spoiled = replace(obs, before={**obs.before, "top": replace(view, depth=depth)})
    verdict = CRITIC.judge(spoiled)
    assert not verdict.accept
    assert "short of pressing clock" in verdict.reason


def test_a_stray_pixel_inside_a_cabinet_does_not_shrink_how_far_its_drawer_is_out() -> None:
    """A drawer left half open, with one pixel inside the cabinet's outline reading 6 cm above its top
    (a stray depth, as seen on rollouts): the cabinet's scale comes from its type's range, so the
    drawer still measures as out, not as shut."""
    result = observed(faulted("closed", "pull_short", 2))
    obs = result.obs
    view = obs.after["top"]
    cab = view.segmentation == obs.labels.index("cab")
    inner = cab & ~np.roll(~cab, 1, axis=0) & ~np.roll(~cab, -1, axis=0)
    rows, cols = np.nonzero(inner)
    depth = view.depth.copy()
    depth[rows[len(rows) // 2], cols[len(cols) // 2]] -= 0.06
    verdict = CRITIC.judge(replace(obs, after={**obs.after, "top": replace(view, depth=depth)}))
    assert not verdict.accept and "not shut" in verdict.reason, verdict.reason
