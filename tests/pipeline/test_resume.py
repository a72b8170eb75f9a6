"""Reruns and crashes: a dataset never repeats an episode, its attempt log always matches it, and
``total=True`` completes an interrupted run."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import scripted_critics  # noqa: F401  (registers alternating and reject_all)
from vcage.config import RenderConfig
from vcage.critics import CriticConfig
from vcage.data import DatasetReader
from vcage.data.layout import ATTEMPTS_LOG, RUNS_LOG
from vcage.pipeline.attempt_log import read
from vcage.pipeline.audit import audit
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.generate import generate
from vcage.scene.instantiate import SceneConfig

SHORT = "press the bell"


def _cfg(critic: str = "oracle", attempts: int = 3) -> GenerateConfig:
    return GenerateConfig(scene=SceneConfig(clutter=0), critic=CriticConfig(critic), max_attempts=attempts,
                          render=RenderConfig(cameras=("front",), size=(64, 64)))


def _seeds(out: Path) -> list[int]:
    reader = DatasetReader(out)
    return [int(reader.extras(i)["seed"]) for i in range(reader.num_episodes)]


def _logged(out: Path) -> list[int]:
    return [int(r["seed"]) for r in read(out / ATTEMPTS_LOG) if r["stage"] == "accepted"]


def test_a_rerun_continues_after_a_given_up_episode_and_never_repeats_one(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    first = generate(SHORT, 3, out, _cfg("alternating", attempts=1))
    assert (first.accepted, first.given_up, first.dataset_episodes) == (2, 1, 2)
    second = generate(SHORT, 1, out, _cfg("alternating", attempts=1))  # a new critic: accepts first
    assert second.accepted == 1 and second.dataset_episodes == 3
    reader = DatasetReader(out)
    assert [reader.extras(i)["sample"] for i in range(3)] == [0, 2, 3]  # sample 1 was given up
    assert len(set(_seeds(out))) == 3
    assert sorted(_logged(out)) == sorted(_seeds(out))
    assert [r["episode"] for r in read(out / ATTEMPTS_LOG)] == [0, 1, 2, 3]
    runs = read(out / RUNS_LOG)
    assert [(r["accepted"], r["given_up"], r["dataset_episodes"]) for r in runs] == [(2, 1, 2), (1, 0, 3)]


def test_total_completes_a_dataset_and_then_has_nothing_to_do(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    generate(SHORT, 1, out, _cfg())
    more = generate(SHORT, 3, out, _cfg(), total=True)
    assert (more.episodes_requested, more.accepted, more.dataset_episodes) == (2, 2, 3)
    done = generate(SHORT, 3, out, _cfg(), total=True)
    assert (done.episodes_requested, done.attempts, done.dataset_episodes) == (0, 0, 3)
    assert len(set(_seeds(out))) == 3 and sorted(_logged(out)) == sorted(_seeds(out))


def test_the_log_is_reconciled_with_the_dataset_when_reopened(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    generate(SHORT, 2, out, _cfg())
    log = out / ATTEMPTS_LOG
    lines = log.read_text().splitlines()
    seeds = _seeds(out)
    # a crash after the second episode committed but before its lines were appended, during the
    # append of a line, and a stale accepted line of an episode the dataset does not hold
    kept = [ln for ln in lines if json.loads(ln)["seed"] != seeds[1]]
    stale = {**json.loads(kept[0]), "episode": 9, "seed": 123}
    log.write_text("\n".join([*kept, json.dumps(stale)]) + '\n{"episode": 1, "att')
    generate(SHORT, 2, out, _cfg(), total=True)  # nothing to generate; the log is reconciled
    assert sorted(_logged(out)) == sorted(seeds)
    assert log.read_text().splitlines() == lines  # exactly the lines a clean run wrote
    assert audit(out).accepted == 2
    # and the next run continues after the samples the log holds, not after the stale one
    nxt = generate(SHORT, 1, out, _cfg())
    assert nxt.accepted == 1 and DatasetReader(out).extras(2)["sample"] == 2


def test_nothing_accepted_is_a_partial_result_and_writes_nothing(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    funnel = generate(SHORT, 2, out, _cfg("reject_all", attempts=2))
    assert (funnel.accepted, funnel.given_up, funnel.attempts, funnel.dataset_episodes) == (0, 2, 4, 0)
    assert funnel.stages == {"critic": 4}
    assert not out.exists()  # nothing is persisted before a first episode commits


def test_episodes_must_be_positive_unless_total(tmp_path: Path) -> None:
    from vcage.errors import ConfigError

    with pytest.raises(ConfigError, match="episodes"):
        generate(SHORT, 0, tmp_path / "ds", _cfg())
    assert not (tmp_path / "ds").exists()


def test_audit_refuses_a_corrupt_log_that_a_writer_would_reconcile(tmp_path: Path) -> None:
    from vcage.errors import DatasetError

    out = tmp_path / "ds"
    generate(SHORT, 1, out, _cfg())
    log = out / ATTEMPTS_LOG
    clean = log.read_text()
    log.write_text(clean + '{"episode": 1, "att')  # torn while appending
    with pytest.raises(DatasetError, match="line 2 is not JSON"):
        audit(out)  # the audit reports it; it does not guess
    generate(SHORT, 1, out, _cfg(), total=True)  # reopening for writing drops the torn line
    assert log.read_text() == clean and audit(out).accepted == 1
