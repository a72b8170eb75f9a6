"""The pipeline's rejection paths through the real sampling loop, writer and audit: a rejected
attempt re-samples the scene, an episode that uses up its attempts is given up, an accepted
failure is label noise, and the audit's counts add up to what the critics and the oracle said.

The critics are scripted (``tests/scripted_critics.py``) so each path is taken on purpose; the
oracle is the real one, and a subtask is made to fail it by a predicate its skill cannot make
true (a retreat never presses the bell).
"""

from __future__ import annotations

from pathlib import Path

import pytest

import scripted_critics  # noqa: F401  (registers accept_all, alternating and reject_all)
from vcage.config import RenderConfig
from vcage.critics import CriticConfig
from vcage.data import DatasetReader
from vcage.data.layout import ATTEMPTS_LOG
from vcage.pipeline.attempt_log import read
from vcage.pipeline.audit import audit
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.episode import Attempt, Timing
from vcage.pipeline.generate import Funnel, _count, generate
from vcage.pipeline.sampling import log_record
from vcage.pipeline.stage import Stage
from vcage.planning import make_planner
from vcage.planning.schema import Plan, Predicate, Subtask
from vcage.scene.instantiate import SceneConfig

SHORT = "press the bell"


def _cfg(critic: str, attempts: int) -> GenerateConfig:
    return GenerateConfig(scene=SceneConfig(clutter=1), render=RenderConfig(size=(64, 64)),
                          critic=CriticConfig(critic), max_attempts=attempts)


def _failing_plan() -> Plan:
    """Press the bell (the oracle agrees), then a retreat that claims to press it (it cannot)."""
    plan = make_planner("offline").plan(SHORT)
    claim = Subtask(skill="retreat", description="the bell is pressed again",
                    predicates=(Predicate(name="pressed", args=("bell",)),))
    return plan.model_copy(update={"subtasks": (plan.subtasks[0], claim)})


def test_a_rejected_attempt_is_resampled_with_a_new_seed(tmp_path: Path) -> None:
    funnel = generate(SHORT, 2, tmp_path, _cfg("alternating", attempts=2))  # accept, reject, accept
    assert funnel.accepted == 2 and funnel.attempts == 3 and funnel.given_up == 0
    assert funnel.stages["critic"] == 1 and funnel.stages["accepted"] == 2
    log = read(tmp_path / ATTEMPTS_LOG)
    assert [(r["episode"], r["attempt"], r["stage"]) for r in log] == [
        (0, 0, "accepted"), (1, 0, "critic"), (1, 1, "accepted")]
    assert log[1]["seed"] != log[2]["seed"] and "call 2" in log[1]["reason"]
    assert DatasetReader(tmp_path).episode(1).extras["attempt"] == 1
    report = audit(tmp_path)
    assert (report.attempts, report.accepted, report.judged_subtasks) == (3, 2, 3)
    assert (report.true_accept, report.false_reject) == (2, 1)  # the oracle says every press worked
    assert report.agreement == pytest.approx(2 / 3) and report.label_noise == 0.0


def test_an_episode_that_uses_up_its_attempts_is_given_up(tmp_path: Path) -> None:
    funnel = generate(SHORT, 1, tmp_path / "none", _cfg("reject_all", attempts=3))
    assert funnel.accepted == 0 and funnel.given_up == 1 and funnel.attempts == 3
    assert funnel.stages["critic"] == 3 and funnel.dataset_episodes == 0
    assert not (tmp_path / "none" / "meta" / "info.json").exists()  # nothing accepted, nothing written
    funnel = generate(SHORT, 3, tmp_path / "ds", _cfg("alternating", attempts=1))  # accept, reject, accept
    assert (funnel.accepted, funnel.given_up, funnel.attempts) == (2, 1, 3)
    log = read(tmp_path / "ds" / ATTEMPTS_LOG)
    assert [(r["episode"], r["stage"]) for r in log] == [(0, "accepted"), (1, "critic"), (2, "accepted")]
    assert [DatasetReader(tmp_path / "ds").episode(i).extras["sample"] for i in range(2)] == [0, 2]
    report = audit(tmp_path / "ds")
    assert (report.attempts, report.accepted, report.judged_subtasks) == (3, 2, 3)
    assert (report.true_accept, report.false_reject, report.false_accept, report.true_reject) == (2, 1, 0, 0)


def test_a_critic_that_accepts_a_failure_records_label_noise(tmp_path: Path) -> None:
    funnel = generate(SHORT, 1, tmp_path, _cfg("accept_all", attempts=2), plan=_failing_plan())
    assert funnel.accepted == 1 and funnel.accepted_oracle_failed == 1 and funnel.label_noise == 1.0
    extras = DatasetReader(tmp_path).episode(0).extras
    assert not extras["oracle_success"]
    assert [row["oracle_success"] for row in extras["oracle_audit"]] == [True, False]
    report = audit(tmp_path)
    assert (report.attempts, report.accepted, report.accepted_oracle_failed) == (1, 1, 1)
    assert (report.true_accept, report.false_accept, report.false_reject, report.true_reject) == (1, 1, 0, 0)
    assert report.label_noise == 1.0 and report.agreement == 0.5
    assert report.precision == 0.5 and report.recall == 1.0


def test_the_oracle_critic_rejects_the_failure_and_gives_up(tmp_path: Path) -> None:
    funnel = generate(SHORT, 1, tmp_path, _cfg("oracle", attempts=2), plan=_failing_plan())
    assert funnel.accepted == 0 and funnel.given_up == 1 and funnel.stages["critic"] == 2
    assert dict(funnel.reasons) == {("critic", "pressed.false"): 2}  # the oracle's code, from its verdict
    assert funnel.label_noise == 0.0 and not (tmp_path / "meta" / "info.json").exists()


def test_the_funnel_counts_rejections_by_their_codes_and_records_without_codes_by_text() -> None:
    """A rejection the critic coded counts under its first code, whatever its text; one without codes
    (a skill's failure, a critic that gives none, a log written before codes were) under its text."""
    funnel = Funnel()
    shallow, missed = ("pressed.too_shallow",), ("on.not_over_target", "released.still_touching")
    records = [log_record(0, i, Attempt(7, Stage.CRITIC, f"subtask 1: pressed(bell): {mm} mm short",
                                        codes=codes))
               for i, (mm, codes) in enumerate([(3.1, shallow), (1.2, shallow), (0.0, missed), (2.5, ())])]
    records.append(log_record(0, 4, Attempt(7, Stage.SKILL, "no grasp at 3 cm")))
    assert [r.get("codes") for r in records] == [list(shallow), list(shallow), list(missed), None, None]
    for record in records:
        _count(funnel, record, Timing())
    assert dict(funnel.reasons) == {("critic", "pressed.too_shallow"): 2, ("critic", "on.not_over_target"): 1,
                                    ("critic", "subtask N: pressed(bell): N mm short"): 1,
                                    ("skill", "no grasp at N cm"): 1}
