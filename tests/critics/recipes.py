"""How each stored observation of ``tests/critics/observations/`` was made, and the command that makes
them again.

The critic's tests judge what the critic was shown of real rollouts: a small scene, one subtask, a
fault injected into its skill (nothing teleported); a scene done as planned whose views after (or
before) are replaced by the same scene with one object dropped in a given orientation and settled
(no injected fault leaves an object so reliably); or one subtask of a Vanilla episode of a benchmark
goal, as ``benchmarks/critic_agreement.py`` rolls it out. Such rollouts are chaotic: a patch release
of the simulator moves them. So the tests read them from files (``save_observation``), and this
module is how the files are made, by name:

    .venv/bin/python tests/critics/recipes.py                 # every case whose file is missing
    .venv/bin/python tests/critics/recipes.py --all           # every case, again
    .venv/bin/python tests/critics/recipes.py NAME [NAME ...]

``tests/regenerate/test_critic_observations.py`` checks (as a slow test) that every case still comes
out as stored under the locked versions: the same oracle values, and the same verdict of the critic.
Each recipe also checks what its case is meant to show of the oracle (the failure is real, the scene
done as planned succeeds) and raises if it does not.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field, replace
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from vcage.critics.base import Observation, Recorder, View
from vcage.critics.observation_file import load_observation, save_observation
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.episode import Timing, attempt
from vcage.pipeline.rollout import run_plan
from vcage.planning import make_planner
from vcage.planning.goals import GOALS, close_drawer, hang, open_drawer, press, put_in, put_on, turn_to_face
from vcage.planning.schema import Plan, PlanObject, Predicate, Subtask
from vcage.scene.compose import compose
from vcage.scene.spec import ObjectSpec as O
from vcage.scene.spec import SceneSpec
from vcage.sim.render import Renderer
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.skills.faults import FaultConfig, FaultInjector
from vcage.skills.playback import Player
from vcage.tasks import predicates as P
from vcage.tasks.verifier import Verifier, render_views

HERE = Path(__file__).parent / "observations"


@dataclass(frozen=True)
class Frozen:
    """A stored observation and what was recorded beside it: ``oracle`` (the subtask's predicate values
    in the simulator), ``applied`` (whether the injected fault acted), and for a settled replacement
    ``placed`` (whether the oracle counts the placing predicates true of the settled scene)."""

    obs: Observation
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def oracle(self) -> dict[str, bool]:
        return dict(self.extra["oracle"])

    @property
    def success(self) -> bool:
        return all(self.oracle.values())


def observed(name: str) -> Frozen:
    """The stored case ``name``."""
    path = HERE / f"{name}.npz"
    if not path.is_file():
        raise FileNotFoundError(f"no stored observation {path}: make it with "
                                f"`.venv/bin/python tests/critics/recipes.py {name}`")
    return Frozen(*load_observation(path))


# ---------------------------------------------------------------- the scenes and faults under test

def _sub(skill: str, args: dict[str, object], *preds: tuple[str, tuple[str, ...]]) -> Subtask:
    return Subtask(skill=skill, args=args, description="a subtask under test",
                   predicates=tuple(Predicate(name=n, args=a) for n, a in preds))


BLOCK_PAD = (O("block", "block", (0.5, -0.12)), O("pad", "mouse_pad", (0.58, 0.1)))
BREAD_BASKET = (O("bread", "bread", (0.5, -0.12)), O("basket", "basket", (0.58, 0.12)))
BELL = (O("bell", "bell", (0.55, 0.05)),)
CLOCK = (O("clock", "alarm_clock", (0.55, 0.05)),)
STAPLER = (O("stapler", "stapler", (0.55, -0.05), yaw=1.0),)
MOUSE_PAD = (O("mouse", "mouse", (0.5, -0.12)), O("pad", "mouse_pad", (0.55, 0.12)))
TWO_BLOCKS = (O("a", "block", (0.5, -0.15)), O("b", "block", (0.55, 0.1)))
STACK = (O("a", "block", (0.5, -0.12)), O("b", "block", (0.55, 0.1)))
ROW_LEFT = (O("a", "block", (0.5, -0.1)), O("b", "block", (0.55, 0.05)))
ROW_RIGHT = (O("a", "block", (0.5, 0.1)), O("b", "block", (0.55, -0.05)))
CABINET = (O("cab", "cabinet", (0.68, 0.05), yaw=-0.2),)
BOARD_AWAY = (O("board", "qr_board", (0.55, 0.1)),)  # its code faces +x, away from the robot
MUG_RACK = (O("mug", "mug", (0.45, -0.12)), O("rack", "mug_rack", (0.63, 0.08)))
BOARD_SIDEWAYS = (O("board", "qr_board", (0.55, 0.0), yaw=np.pi / 2),)  # its code faces the robot's left
CUP_COASTER = (O("cup", "cup", (0.5, -0.12)), O("coaster", "coaster", (0.58, 0.1)))
SEAL_MAT = (O("seal", "seal", (0.5, -0.12)), O("mat", "stamp_mat", (0.58, 0.1)))

SCENARIOS: dict[str, tuple[tuple[O, ...], Subtask]] = {
    "on": (BLOCK_PAD, put_on("block", "pad", "the block is on the pad")),
    # the pad under the hand's home: a mouse never let go is carried back over it
    "on_home": ((O("mouse", "mouse", (0.55, -0.12)), O("pad", "mouse_pad", (0.45, 0.0))),
                put_on("mouse", "pad", "the mouse is on the pad")),
    "inside": (BREAD_BASKET, put_in("bread", "basket", "the bread is in the basket")),
    "pressed": (BELL, press("bell", "the bell is rung")),
    "upright": (CLOCK, press("clock", "the clock's button is pressed")),
    "pressed_lever": (STAPLER, press("stapler", "the stapler is pressed")),
    "on_table": (MOUSE_PAD, _sub("pick_and_place", {"obj": "mouse", "xy": [0.55, 0.02]},
                                 ("on_table", ("mouse",)), ("released", ("mouse",)))),
    "near": (TWO_BLOCKS, _sub("pick_and_place", {"obj": "a", "xy": [0.55, 0.04]},
                              ("near", ("a", "b")), ("released", ("a",)))),
    "lifted": ((O("block", "block", (0.55, 0.0)),), _sub("grasp", {"obj": "block"}, ("lifted", ("block",)))),
    "stacked": (STACK, _sub("pick_and_place", {"obj": "a", "target": "b"},
                            ("stacked", ("b", "a")), ("released", ("a",)))),
    "left_of": (ROW_LEFT, _sub("pick_and_place", {"obj": "a", "xy": [0.5, 0.18]},
                               ("left_of", ("a", "b")), ("released", ("a",)))),
    "right_of": (ROW_RIGHT, _sub("pick_and_place", {"obj": "a", "xy": [0.5, -0.18]},
                                 ("right_of", ("a", "b")), ("released", ("a",)))),
    "opened": (CABINET, open_drawer("cab", "the drawer is open")),
    "closed": (CABINET, close_drawer("cab", "the drawer is shut")),  # after opening it (BEFORE)
    "inside_drawer": ((*CABINET, O("soap", "soap", (0.5, -0.15))),
                      put_in("soap", "cab", "the soap is in the open drawer")),  # after opening it
    "facing": (BOARD_SIDEWAYS, turn_to_face("board", "the board faces the robot")),
    "hanging": (MUG_RACK, hang("mug", "rack", "the mug hangs on the rack")),
}
BEFORE = {"closed": (open_drawer("cab", "the drawer is open"),),
          "inside_drawer": (open_drawer("cab", "the drawer is open"),)}

# (scenario, fault, seed, the predicate that must fail in the oracle and in the critic's checks)
FAILURES = [
    ("on", "off_target", 1, "on(block, pad)"),
    ("on", "release_late", 2, "on(block, pad)"),
    ("inside", "off_target", 1, "inside(bread, basket)"),
    ("inside", "on_edge", 0, "inside(bread, basket)"),
    ("on", "no_release", 0, "released(block)"),
    ("on_home", "no_release", 0, "on(mouse, pad)"),  # held over the pad, higher than resting on it allows
    ("inside", "no_release", 0, "released(bread)"),  # the bread in the hand shows from the top
    ("pressed", "press_hover", 0, "pressed(bell)"),
    ("pressed", "press_miss", 0, "pressed(bell)"),
    ("upright", "press_miss", 2, "pressed(clock)"),  # touched and deep enough, but beside the button
    ("pressed", "press_light", 0, "pressed(bell)"),
    ("pressed", "press_light", 3, "pressed(bell)"),
    ("upright", "press_light", 1, "pressed(clock)"),
    ("pressed_lever", "press_light", 3, "pressed(stapler)"),
    ("upright", "knock_over", 1, "upright(clock)"),
    ("on_table", "off_target", 2, "on_table(mouse)"),
    ("near", "off_target", 0, "near(a, b)"),
    ("near", "release_early", 0, "near(a, b)"),
    ("lifted", "grasp_miss", 0, "lifted(block)"),
    ("stacked", "off_target", 0, "stacked(b, a)"),
    ("left_of", "wrong_object", 0, "left_of(a, b)"),
    ("right_of", "wrong_object", 0, "right_of(a, b)"),
    ("opened", "pull_short", 1, "opened(cab)"),
    ("closed", "pull_short", 2, "closed(cab)"),
    # over the cabinet's hull, as resting in it would be, but mostly on its body beside the drawer
    ("inside_drawer", "release_late", 1, "inside(soap, cab)"),
    # turned 30-60% of the quarter turn it needed: its plain back shows obliquely to the front camera,
    # as it does when the board faces the robot; only its axis from the top tells
    ("facing", "turn_short", 0, "facing(board)"),
    ("hanging", "hang_short", 0, "hanging(mug, rack)"),  # let go beside the peg's end: it falls on the base
]


def planned(scenario: str) -> str:
    return f"planned-{scenario}"


def faulted(scenario: str, fault: str, seed: int) -> str:
    return f"{scenario}-{fault}-{seed}"


def vanilla(goal: str, episode: int, index: int) -> str:
    return f"vanilla-{goal}-{episode}-{index}"


# ---------------------------------------------------------------- rollouts (MuJoCo, no mocks)

def _run(objects: tuple[O, ...], subtask: Subtask, fault: str | None = None, seed: int = 0,
         before: tuple[Subtask, ...] = ()) -> Frozen:
    """Execute ``subtask`` in a scene of ``objects`` with ``fault`` injected into its skill, after the
    subtasks ``before`` (done as planned; their skills must differ from its own)."""
    world = compose(SceneSpec(objects=objects)).make_world()
    world.settle(0.3)
    plan = Plan(instruction="test", objects=tuple(PlanObject(name=o.name, type=o.type) for o in objects),
                subtasks=(*before, subtask))
    assert all(st.skill != subtask.skill for st in before)
    injector = FaultInjector(FaultConfig(fault, subtask.skill, 0, seed)) if fault else None
    skills = Skills(world, Player(world, record_states=True), fault=injector)
    keep = Recorder()
    with Renderer(world, 320, 240) as renderer:
        verifier = Verifier(world, plan.subtasks, keep, renderer, skills.player.recording, Timing())
        rollout = run_plan(world, plan, skills, verifier)
    outcome = rollout.outcomes[-1]
    assert len(rollout.outcomes) == len(plan.subtasks) and outcome.skill_error is None, outcome.skill_error
    assert all(o.oracle_success for o in rollout.outcomes[:-1]), rollout.outcomes
    return Frozen(keep.seen[-1], {"oracle": dict(outcome.oracle),
                                  "applied": injector is None or injector.applied})


def _scenario(scenario: str, fault: str | None = None, seed: int = 0) -> Frozen:
    objects, subtask = SCENARIOS[scenario]
    return _run(objects, subtask, fault, seed, BEFORE.get(scenario, ()))


def _planned(scenario: str) -> Frozen:
    done = _scenario(scenario)
    assert done.success, done.oracle
    return done


def _failed(scenario: str, fault: str, seed: int, predicate: str) -> Frozen:
    result = _scenario(scenario, fault, seed)
    assert result.extra["applied"] and result.oracle[predicate] is False, result.oracle  # a real failure
    return result


def _vanilla(goal: str, episode: int, index: int) -> Frozen:
    """What the critic was shown of judged subtask ``index`` of Vanilla's episode ``episode`` of ``goal``
    (naive placement and no scene check: the plan's objects may start fused into one another); the
    rollout goes on whatever the critic says."""
    plan = make_planner("offline").plan(next(g for g in GOALS if g.name == goal).phrasings[0])
    cfg = GenerateConfig.vanilla(seed=0)
    keep = Recorder()
    result = attempt(plan, cfg.episode_seed(episode, 0), cfg, keep)
    assert result.rollout is not None, result
    judged = [o for o in result.rollout.outcomes if o.verdict is not None]
    seen = list(zip(keep.seen, judged, strict=True))
    obs, outcome = seen[index]
    return Frozen(obs, {"oracle": dict(outcome.oracle), "applied": True})


def _settled(objects: tuple[O, ...], quat: tuple[float, ...]) -> tuple[World, dict[str, View]]:
    """The scene of ``objects`` with the first dropped from its ``z`` in orientation ``quat``, settled,
    and its views (the segmentation labels follow the objects' order)."""
    world = compose(SceneSpec(objects=objects)).make_world()
    adr = world.model.jnt_qposadr[world.model.body_jntadr[world.object(objects[0].name).body_id]]
    world.data.qpos[adr + 3:adr + 7] = quat
    world.forward()
    world.settle(1.0)
    with Renderer(world, 320, 240) as renderer:
        return world, render_views(renderer)


def _set_down(scene: tuple[O, ...], subtask: Subtask, placed: O, quat: tuple[float, ...],
              extra: tuple[O, ...] = (), moved: tuple[O, ...] = (),
              lay_before: tuple[O, tuple[float, ...]] | None = None) -> Frozen:
    """``subtask`` done as planned in ``scene``, with the "after" views replaced by the same scene (and
    the objects ``extra``, unlabelled; ``moved`` in place of the scene's objects of the same names)
    with ``placed`` dropped from its ``z`` in orientation ``quat`` and settled (no injected fault
    leaves an object in such a pose reliably). ``lay_before``: the "before" views replaced likewise,
    with ``placed`` there as given. ``placed`` in the result: whether the oracle counts the subtask's
    placing predicates true of the settled scene."""
    done = _run(scene, subtask)
    assert done.success, done.oracle
    instead = {o.name: o for o in moved}
    others = tuple(instead.get(o.name, o) for o in scene if o.name != placed.name)
    assert scene[0].name == placed.name  # the segmentation labels keep their order
    world, after = _settled((placed, *others, *extra), quat)
    placing = [p for p in subtask.predicates if p.name != "released"]
    oracle = {str(p): bool(P.ORACLE_CHECKS.get(p.name)(world, *p.args)) for p in placing}
    obs = replace(done.obs, after=after)
    if lay_before is not None:
        obs = replace(obs, before=_settled((lay_before[0], *scene[1:]), lay_before[1])[1])
    return Frozen(obs, {"oracle": oracle, "applied": True})


def _quarter(axis: str) -> tuple[float, float, float, float]:
    c, s = float(np.cos(np.pi / 4)), float(np.sin(np.pi / 4))
    return {"x": (c, s, 0.0, 0.0), "y": (c, 0.0, s, 0.0), "z": (c, 0.0, 0.0, s)}[axis]


def _tilt_y(angle: float) -> tuple[float, float, float, float]:
    return (float(np.cos(angle / 2)), 0.0, float(np.sin(angle / 2)), 0.0)


UPRIGHT = (1.0, 0.0, 0.0, 0.0)
OVER = (0.0, 1.0, 0.0, 0.0)  # half a turn about x
ON_PAD = put_on("mouse", "pad", "the mouse is on the pad")
ON_COASTER = put_on("cup", "coaster", "the cup is on the coaster")
IN_BASKET = put_in("bread", "basket", "the bread is in the basket")
RING = press("bell", "the bell is rung")
LOAF_L = O("bread", "bread", (0.5, -0.12), scale=1.1)
LOAF_S = O("bread", "bread", (0.5, -0.12), scale=0.9)
SMALL_BASKET = O("basket", "basket", (0.58, 0.12), scale=0.9)
SEAL_LYING = (float(np.cos(0.89)), float(np.sin(0.89)), 0.0, 0.0)  # 1.78 rad about x, as they lay
BELL_CUP = (*BELL, O("cup", "cup", (0.62, 0.05)))
BELL_BOX = (*BELL, O("box", "cereal_box", (0.64, 0.05)))
BELL_HOLDER = (*BELL, O("holder", "pen_holder", (0.63, 0.05)))

# The Vanilla episodes whose subtasks tests judge: (goal, episode, index of the judged subtask)
VANILLA = [
    ("tidy_the_desk", 880, 1), ("get_ready_for_work", 852, 2),  # mice turned over at a slant
    ("tidy_the_desk", 871, 1), ("tidy_the_desk", 988, 1),  # mice on the pad, leaning or fused
    ("set_the_table", 816, 0), ("set_the_table", 958, 0),  # cups on their sides, never stood on the table
    ("set_the_table", 945, 0), ("set_the_table", 830, 0),  # cups tilted on the coaster
    ("set_the_table", 912, 1), ("prepare_breakfast", 858, 0),  # loaves across the basket's wall
    ("build_a_tower", 883, 2), ("set_the_table", 863, 2), ("prepare_breakfast", 902, 2),  # leaning bells
]

CASES: dict[str, Callable[[], Frozen]] = {
    **{planned(s): partial(_planned, s) for s in SCENARIOS},
    **{faulted(s, f, seed): partial(_failed, s, f, seed, p) for s, f, seed, p in FAILURES},
    faulted("pressed", "knock_over", 1): partial(_scenario, "pressed", "knock_over", 1),
    **{vanilla(*v): partial(_vanilla, *v) for v in VANILLA},
    "mouse-onto-a-block-on-the-pad": partial(_run, (*MOUSE_PAD, O("block", "block", (0.55, 0.12), z=0.8)),
                                             ON_PAD),
    "mouse-on-its-back-on-the-pad": partial(_set_down, MOUSE_PAD, ON_PAD,
                                            O("mouse", "mouse", (0.55, 0.12), z=0.9), OVER),
    "mouse-on-its-back-before-and-on-the-pad": partial(
        _set_down, MOUSE_PAD, ON_PAD, O("mouse", "mouse", (0.55, 0.12), z=0.9), OVER,
        lay_before=(O("mouse", "mouse", (0.5, -0.12), z=0.9), OVER)),
    "mouse-tipped-at-a-slant-on-the-pad": partial(_set_down, MOUSE_PAD, ON_PAD,
                                                  O("mouse", "mouse", (0.583, 0.107), z=0.8),
                                                  (0.207, -0.625, 0.714, -0.238)),
    "mouse-on-its-end-on-the-pad": partial(_set_down, MOUSE_PAD, ON_PAD,
                                           O("mouse", "mouse", (0.55, 0.12), z=0.85), _quarter("y")),
    "cup-on-its-side-across-the-coaster": partial(_set_down, CUP_COASTER, ON_COASTER,
                                                  O("cup", "cup", (0.58, 0.145), z=0.85), _quarter("x")),
    "cup-on-its-side-over-a-coaster-it-hides": partial(
        _set_down, CUP_COASTER, ON_COASTER, O("cup", "cup", (0.58, 0.145), z=0.85), _quarter("x"),
        moved=(O("coaster", "coaster", (0.585, 0.11)),)),
    "small-cup-standing-on-the-coaster": partial(
        _set_down, (O("cup", "cup", (0.5, -0.12), scale=0.9), O("coaster", "coaster", (0.58, 0.1))),
        ON_COASTER, O("cup", "cup", (0.58, 0.1), z=0.8, scale=0.9), UPRIGHT),
    "cup-moved-to-the-middle-of-a-coaster-it-half-hid": partial(
        _run, (O("cup", "cup", (0.58, 0.08), z=0.755, scale=1.2), O("coaster", "coaster", (0.58, 0.1))),
        ON_COASTER),
    "cup-on-the-coaster-beside-a-turned-basket": partial(
        _set_down, (*CUP_COASTER, O("basket", "basket", (0.4, 0.15))), ON_COASTER,
        O("cup", "cup", (0.58, 0.1), z=0.8), UPRIGHT, moved=(O("basket", "basket", (0.71, 0.142), yaw=0.5),)),
    "seal-on-its-side-before-and-on-the-mat": partial(
        _set_down, SEAL_MAT, put_on("seal", "mat", "the seal is on the mat"),
        O("seal", "seal", (0.58, 0.13), z=0.8), SEAL_LYING,
        lay_before=(O("seal", "seal", (0.5, -0.12), z=0.8), SEAL_LYING)),
    "loaf-upside-down-in-the-basket": partial(_set_down, BREAD_BASKET, IN_BASKET,
                                              O("bread", "bread", (0.58, 0.12), z=0.8), OVER),
    "loaf-on-its-end-in-the-basket": partial(_set_down, (LOAF_L, SMALL_BASKET), IN_BASKET,
                                             replace(LOAF_L, xy=(0.58 - 0.034, 0.12), z=0.83), _quarter("y")),
    "loaf-leaning-against-the-rim-underside": partial(_set_down, (LOAF_L, SMALL_BASKET), IN_BASKET,
                                                      replace(LOAF_L, xy=(0.62, 0.12), z=0.83), _tilt_y(0.8)),
    "loaf-leaning-against-the-rim-top": partial(_set_down, (LOAF_S, SMALL_BASKET), IN_BASKET,
                                                replace(LOAF_S, xy=(0.62, 0.12), z=0.83), _tilt_y(0.6)),
    "loaf-leaning-on-a-cup-in-the-basket": partial(
        _set_down, (O("bread", "bread", (0.5, -0.12)), O("basket", "basket", (0.58, 0.12)),
                    O("cup", "cup", (0.625, 0.12), z=0.735)),
        IN_BASKET, O("bread", "bread", (0.57, 0.12), z=0.83), _tilt_y(-0.6)),
    "loaf-lying-on-a-cup-above-the-rim": partial(_set_down, BREAD_BASKET, IN_BASKET,
                                                 O("bread", "bread", (0.58, 0.12), z=0.9), UPRIGHT,
                                                 extra=(O("cup", "cup", (0.58, 0.12), z=0.735),)),
    "loaf-bridging-the-rims": partial(_set_down, (LOAF_L, SMALL_BASKET), IN_BASKET,
                                      replace(LOAF_L, xy=(0.58, 0.12), z=0.83), _quarter("z")),
    "loaf-level-against-the-wall-inside": partial(_set_down, BREAD_BASKET, IN_BASKET,
                                                  O("bread", "bread", (0.58, 0.185), z=0.76), UPRIGHT),
    "block-diagonally-off-centre-on-a-block": partial(
        _set_down, STACK, _sub("pick_and_place", {"obj": "a", "target": "b"}, ("on", ("a", "b")),
                               ("released", ("a",))),
        O("a", "block", (0.55 + 0.016, 0.1 + 0.015), z=0.79), UPRIGHT),
    "block-put-down-where-another-stands": partial(
        _run, (O("a", "block", (0.5, -0.12)), O("b", "block", (0.55, 0.05))),
        _sub("pick_and_place", {"obj": "a", "xy": [0.55, 0.05]}, ("on_table", ("a",)), ("released", ("a",)))),
    "bell-behind-a-cup": partial(_run, BELL_CUP, RING),
    "bell-behind-a-cup-press_miss-0": partial(_run, BELL_CUP, RING, "press_miss", 0),
    "bell-behind-a-box": partial(_run, BELL_BOX, RING),
    "bell-behind-a-box-press_hover-0": partial(_run, BELL_BOX, RING, "press_hover", 0),
    "bell-behind-a-holder": partial(_run, BELL_HOLDER, RING),
    "bell-behind-a-holder-press_miss-0": partial(_run, BELL_HOLDER, RING, "press_miss", 0),
    "bell-behind-a-holder-press_light-0": partial(_run, BELL_HOLDER, RING, "press_light", 0),
    "clock-rocking-onto-a-marker": partial(
        _run, (O("clock", "alarm_clock", (0.55, 0.05), z=0.765), O("marker", "marker", (0.55, 0.075))),
        press("clock", "the clock's button is pressed")),
    "board-put-back-unturned": partial(
        _run, BOARD_AWAY, _sub("pick_and_place", {"obj": "board", "xy": list(BOARD_AWAY[0].xy)},
                               ("facing", ("board",)), ("released", ("board",)))),
    "mug-hung-on-the-other-rack": partial(
        _run, (*MUG_RACK, O("other", "mug_rack", (0.45, 0.25))),
        _sub("hang", {"obj": "mug", "target": "rack"}, ("hanging", ("mug", "other")),
             ("released", ("mug",)))),
}


def make(name: str) -> str:
    """Roll case ``name`` out and store it; returns the file's name."""
    frozen = CASES[name]()
    HERE.mkdir(exist_ok=True)
    save_observation(HERE / f"{name}.npz", frozen.obs, {**frozen.extra, "case": name})
    return name


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("names", nargs="*", help="cases to make (default: those whose file is missing)")
    parser.add_argument("--all", action="store_true", help="make every case again")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    unknown = [n for n in args.names if n not in CASES]
    if unknown:
        parser.error(f"unknown cases {unknown}; valid: {sorted(CASES)}")
    names = args.names or [n for n in CASES if args.all or not (HERE / f"{n}.npz").is_file()]
    stale = sorted(p.stem for p in HERE.glob("*.npz") if p.stem not in CASES)
    with ProcessPoolExecutor(args.workers) as pool:
        for done in pool.map(make, names):
            print(f"stored {done}", flush=True)
    if stale:
        print(f"files of no case (remove them): {stale}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    raise SystemExit(main())
