"""Silent-failure injection: a registry of named, seeded faults hooked into ``Skills.do``.

With no fault (or one that never fires) a rollout is the same, value for value; a fault is
reproducible from its seed, runs without error, and makes the oracle see a failure.
"""

from __future__ import annotations

import numpy as np
import pytest

from vcage.errors import ConfigError
from vcage.scene.compose import compose
from vcage.scene.spec import ObjectSpec, SceneSpec
from vcage.skills.base import SKILLS, Skills
from vcage.skills.faults import FAULTS, FaultConfig, FaultInjector, faults_for
from vcage.skills.playback import Player
from vcage.tasks.predicates import on, pressed

SCENE = SceneSpec(objects=(ObjectSpec("block", "block", (0.5, -0.12)),
                           ObjectSpec("pad", "mouse_pad", (0.58, 0.1)),
                           ObjectSpec("bell", "bell", (0.62, -0.1)),
                           ObjectSpec("other", "block", (0.45, -0.2))))


def _rollout(fault: FaultConfig | None, skill: str = "pick_and_place", **args: object
             ) -> tuple[dict[str, np.ndarray], Skills, FaultInjector | None]:
    world = compose(SCENE).make_world()
    world.settle(0.3)
    injector = FaultInjector(fault) if fault is not None else None
    skills = Skills(world, Player(world, record_states=True), fault=injector)
    skills.do(skill, **(args or {"obj": "block", "target": "pad"}))
    skills.do("retreat")
    arrays = skills.player.recording.arrays()
    arrays["states"] = np.asarray(skills.player.recording.states)
    return arrays, skills, injector


def test_every_fault_perturbs_registered_skills_and_every_plan_skill_has_faults() -> None:
    for spec in FAULTS.values():
        assert spec.doc and all(s in SKILLS for s in spec.skills), spec.name
    for skill in ("pick_and_place", "press", "grasp", "turn_and_place", "move_line", "shake"):
        assert faults_for(skill)


def test_configs_are_validated_and_unknown_names_list_the_valid_ones() -> None:
    with pytest.raises(ConfigError, match="off_target"):
        FaultConfig("teleport")
    with pytest.raises(ConfigError, match="applies to"):
        FaultConfig("press_light", skill="pick_and_place")
    with pytest.raises(ConfigError, match="occurrence"):
        FaultConfig("off_target", occurrence=-1)


def test_a_fault_that_never_fires_leaves_the_rollout_identical() -> None:
    clean, _, _ = _rollout(None)
    idle, _, injector = _rollout(FaultConfig("off_target", "pick_and_place", occurrence=1))
    assert injector is not None and not injector.applied
    for key, value in clean.items():
        assert np.array_equal(value, idle[key]), key


def test_a_fault_is_reproducible_from_its_seed_and_the_seed_matters() -> None:
    _, clean, _ = _rollout(None)
    a, sa, _ = _rollout(FaultConfig("off_target", seed=3))
    b, _, _ = _rollout(FaultConfig("off_target", seed=3))
    c, _, _ = _rollout(FaultConfig("off_target", seed=4))
    assert np.array_equal(a["states"], b["states"])
    assert not np.array_equal(a["states"][-1], c["states"][-1])
    miss = np.linalg.norm(sa.world.object_pos("block")[:2] - clean.world.object_pos("block")[:2])
    assert 0.05 < miss < 0.15  # ran without error, 6-12 cm from where it should be


def test_no_release_carries_the_object_away_and_press_hover_never_presses() -> None:
    _, s, inj = _rollout(FaultConfig("no_release"))
    assert inj is not None and inj.applied and "no_release" in inj.note
    assert s.world.object_pos("block")[2] > s.world.table_top() + 0.1  # still in the hand
    _, s, inj = _rollout(FaultConfig("press_hover"), "press", obj="bell")
    assert inj is not None and inj.applied and not pressed(s.world, "bell")


def test_wrong_object_moves_another_object_and_after_faults_need_a_next_call() -> None:
    _, s, inj = _rollout(FaultConfig("wrong_object"))
    assert inj is not None and inj.applied
    assert not on(s.world, "block", "pad")
    world = compose(SCENE).make_world()
    injector = FaultInjector(FaultConfig("knock_over"))
    Skills(world, fault=injector).do("press", obj="bell")
    assert not injector.applied  # it acts on the result: planned before the next call


NEW_SKILL_FAULTS = [("rotate_qrcode", "turn_short"), ("beat_block_hammer", "stop_short"),
                    ("shake_bottle", "shake_weak")]


@pytest.mark.parametrize(("task", "fault"), NEW_SKILL_FAULTS)
def test_the_new_skills_faults_run_cleanly_and_fail_the_task_the_expert_solves(task: str, fault: str) -> None:
    from vcage.config import Randomization
    from vcage.tasks.engine import held
    from vcage.tasks.runner import prepare

    outcome = {}
    for name in (None, fault):
        t, world, _ = prepare(task, 0, Randomization())
        injector = FaultInjector(FaultConfig(name, seed=1)) if name else None
        skills = Skills(world, fault=injector)
        skills.player.hooks.append(t.on_step)
        t.expert(skills)  # a silent failure: nothing raises
        holds, _ = held(skills, lambda t=t, skills=skills: t.evaluate(skills.world), t.hold_steps)
        outcome[name] = holds["success"]
        assert injector is None or injector.applied
    assert outcome == {None: True, fault: False}
