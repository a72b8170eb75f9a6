"""Verification in MuJoCo: seeded trials, oracle and critic, SR > 0.5, the funnel, the database."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from scripted_critics import RejectAll
from vcage.critics.base import CriticConfig, make_critic
from vcage.scene.spec import ObjectSpec, SceneSpec
from vcage.subtasks.candidates import Candidate, candidates
from vcage.subtasks.scenes import resolve
from vcage.subtasks.store import SubtaskStore
from vcage.subtasks.trial import TrialConfig, run_trial
from vcage.subtasks.verify import verify, verify_all

CFG = TrialConfig(trials=2)


@pytest.fixture(scope="module")
def stapler():  # type: ignore[no-untyped-def]
    scene, spec = resolve("task:press_stapler")
    (press,) = candidates(scene.id, spec)
    return scene, spec, press


def _program(press: Candidate, code: str) -> Candidate:
    return press.with_program(code, model="replay", prompt_hash="0" * 64)


def test_a_scene_is_verified_into_the_database_with_the_funnel(stapler, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    scene, spec, press = stapler
    silent = _program(press, "retreat()\n")  # runs, plans, does nothing: a silent failure
    malicious = _program(press, "().__class__.__bases__[0].__subclasses__()\n")
    nan = _program(press, "press(obj='stapler', depth=float('nan'))\n")
    db = tmp_path / "s.db"
    with SubtaskStore(db) as store:
        funnel = verify_all(scene, spec, [press, silent, malicious, nan], store,
                            make_critic(CriticConfig("image")), CFG, "image")
        rows = {r.id: r for r in store.subtasks()}
        trials = {r.id: store.get(r.id)[1] for r in rows.values()}
    assert funnel.to_dict() == {"candidates": 4, "valid": 3, "ran": 2, "succeeded": 1, "accepted": 1}
    good = rows[press.id]
    assert (good.status, good.successes, good.trials, good.success_rate) == ("accepted", 2, 2, 1.0)
    assert good.ci_low == pytest.approx(0.342, abs=1e-3) and good.ci_high == 1.0
    assert good.source == "template" and good.critic == "image" and good.versions["mujoco"]
    assert good.versions["critic"] == make_critic(CriticConfig("image")).version()  # image@<rules digest>
    assert [t.outcome for t in trials[press.id]] == ["success", "success"]
    assert rows[silent.id].status == "rejected" and rows[silent.id].source == "llm"
    assert {t.failure_class for t in trials[silent.id]} == {"oracle"}
    assert rows[malicious.id].trials == 0 and rows[malicious.id].reason.startswith("invalid: ")
    assert {t.failure_class for t in trials[nan.id]} == {"invalid_call"}
    assert "not a finite number" in trials[nan.id][0].detail


def test_trial_outcomes_are_identical_on_rerun(stapler) -> None:  # type: ignore[no-untyped-def]
    _, spec, press = stapler
    program = _program(press, "p = position('stapler')\npress(obj='stapler', point='press')\n")
    first = [run_trial(program, spec, k, None, CFG) for k in range(2)]
    again = [run_trial(program, spec, k, None, CFG) for k in range(2)]
    assert [replace(t, seconds=0) for t in first] == [replace(t, seconds=0) for t in again]
    assert first[0].seed != first[1].seed and all(t.success for t in first)


def test_a_critic_rejection_fails_the_trial_even_when_the_oracle_holds(stapler) -> None:  # type: ignore[no-untyped-def]
    _, spec, press = stapler
    record, trials, funnel = verify(press, spec, RejectAll(), TrialConfig(trials=1), "reject_all")
    assert trials[0].failure_class == "critic" and trials[0].detail == "rejects everything"
    assert record.status == "rejected" and funnel.ran == 1 and funnel.succeeded == 0


def test_a_goal_that_holds_before_the_robot_acts_verifies_nothing() -> None:
    """A synthesized scene is a goal arrangement: a program that does nothing must not pass there."""
    on_top = SceneSpec(objects=(ObjectSpec("dish", "plate", (0.55, 0.1)),
                                ObjectSpec("cube", "block", (0.55, 0.1), z=0.75 + 0.004)))
    cube_on_dish = next(c for c in candidates("s", on_top) if c.args == {"obj": "cube", "target": "dish"})
    idle = _program(cube_on_dish, "retreat()\n")
    trial = run_trial(idle, on_top, 0, None, TrialConfig(trials=1, jitter_xy=0.0, jitter_yaw=0.0))
    assert (trial.outcome, trial.failure_class) == ("failure", "already_holds")
