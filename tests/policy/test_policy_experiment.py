"""The policy experiment's smoke path (``--quick``): the whole loop runs end to end and resumes.

Only that it runs is asserted, never a success figure (two demos and four training steps mean
nothing)."""

from __future__ import annotations

import importlib.util
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

from conftest import blocked_modules

pytestmark = pytest.mark.slow  # runs the policy experiment's stages as subprocesses

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "policy_vcage_vs_vanilla.py"


def run(work: Path, *extra: str, env: dict[str, str] | None = None, ok: bool = True) -> str:
    done = subprocess.run([sys.executable, str(SCRIPT), "--work", str(work), "--quick", *extra],
                          capture_output=True, text=True, timeout=600,
                          env={**os.environ, "LP_NUM_THREADS": "1", **(env or {})})
    assert (done.returncode == 0) == ok, done.stdout + done.stderr
    return done.stdout + done.stderr


def test_the_quick_experiment_runs_end_to_end_and_resumes(tmp_path: Path) -> None:
    first = run(tmp_path)
    for line in ("Avg SR", "Top-5 (tasks)", "Top-5 (ckpts)", "V-CAGE - Vanilla success gap",
                 "paired bootstrap 95%", f"learning curves: {tmp_path / 'learning_curves.png'}"):
        assert line in first, first
    assert (tmp_path / "learning_curves.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    results = sorted(p.relative_to(tmp_path).as_posix() for p in (tmp_path / "results").rglob("*.json"))
    assert results == ["results/press_the_bell/vanilla/seed0.json", "results/press_the_bell/vcage/seed0.json"]
    for path in (tmp_path / "results").rglob("*.json"):  # each checkpoint also ran on one training scene
        fit = json.loads(path.read_text())["fit"]  # of its own dataset, built by that dataset's sampler
        assert fit["episodes"] == 1 and fit["environment"] == str(tmp_path / "data" / "press_the_bell" /
                                                                   path.parent.name)
    stamps = {p: p.stat().st_mtime_ns for p in (tmp_path / "results").rglob("*.json")}
    second = run(tmp_path)  # everything is done: read back, nothing generated, trained or evaluated again
    assert "(0 attempts this run)" in second
    assert {p: p.stat().st_mtime_ns for p in stamps} == stamps
    assert first.split("task ")[1].split("\n\n")[0] == second.split("task ")[1].split("\n\n")[0]


def test_the_stages_run_apart_and_training_needs_no_simulator(tmp_path: Path) -> None:
    """Data here, training where neither the simulator nor the codec is installed (as on a GPU
    machine), evaluation of the exported checkpoints back here in a work folder without the runs."""
    work, exported, blocked = tmp_path / "work", tmp_path / "exported", blocked_modules(tmp_path / "blocked")
    run(work, "--stage", "data")
    assert not (work / "runs").exists() and not (work / "results").exists()
    src = str(SCRIPT.parents[1] / "src")
    trained = run(work, "--stage", "train", "--budget", "1", "--export", str(exported),
                  env={"PYTHONPATH": os.pathsep.join([str(blocked), src])})
    assert "probe: 1 runs at once" in trained and "2 runs in 2 turns: 1000 steps each" in trained, trained
    assert sorted(p.name for p in exported.iterdir()) == ["press_the_bell.vanilla.seed0.pt",
                                                          "press_the_bell.vcage.seed0.pt"]
    shutil.rmtree(work / "runs")
    refused = run(work, "--stage", "evaluate", ok=False)
    assert "holds no finished training run" in refused
    evaluated = run(work, "--stage", "evaluate", "--import", str(exported))
    assert "Avg SR" in evaluated and "imported" in evaluated
    for method in ("vcage", "vanilla"):
        result = json.loads((work / "results" / "press_the_bell" / method / "seed0.json").read_text())
        record = json.loads((work / "runs" / "press_the_bell" / method / "seed0" / "train.json").read_text())
        assert record["steps"] == 1000 and result["train_samples_per_second"] == record["samples_per_second"]
        assert result["episodes"] == 1


def _experiment() -> ModuleType:
    spec = importlib.util.spec_from_file_location("policy_experiment", SCRIPT)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_failure_kinds_count_what_the_oracle_finds_wrong_in_kept_demos(tmp_path: Path) -> None:
    """Each kept episode that fails the oracle counts once per failed predicate (and per skill error);
    kept successes and rejected attempts count for nothing."""
    def record(stage: str, success: bool, rows: list[dict[str, Any]]) -> str:
        return json.dumps({"stage": stage, "oracle_success": success, "audit": rows})

    on_false = {"skill": "pick_and_place", "oracle": {"on(mouse, pad)": False, "released(mouse)": True}}
    both_false = {"skill": "press", "oracle": {"pressed(bell)": False, "upright(bell)": False},
                  "skill_error": "IK failed"}
    fine = {"skill": "press", "oracle": {"pressed(bell)": True, "upright(bell)": True}}
    log = tmp_path / "meta" / "vcage_attempts.jsonl"
    log.parent.mkdir()
    log.write_text("\n".join([
        record("accepted", False, [on_false, fine]),
        record("accepted", False, [on_false, both_false]),
        record("accepted", True, [fine]),
        record("rejected", False, [on_false]),  # not in the dataset
    ]) + "\n")
    kinds = _experiment().failure_kinds(tmp_path)
    assert kinds == {"on(mouse, pad)": 2, "pressed(bell)": 1, "upright(bell)": 1, "skill error in press": 1}
    assert next(iter(kinds)) == "on(mouse, pad)"  # most frequent first


def test_subtask_gaps_count_the_episodes_past_each_subtask(capsys: object) -> None:
    """A goal no policy completes still shows which data teaches its first subtask."""
    def result(method: str, seed: int, done: list[int]) -> dict[str, object]:
        return {"method": method, "train_seed": seed, "subtask_names": ["the mouse on the pad", "the bell"],
                "per_episode": [{"subtasks_done": d, "success": d == 2} for d in done]}

    by = {"goal": {"vcage": [result("vcage", 1, [1, 1, 0, 2]), result("vcage", 0, [1, 0, 0, 0])],
                   "vanilla": [result("vanilla", 0, [0, 0, 0, 0]), result("vanilla", 1, [1, 0, 0, 0])]},
          "one step": {"vcage": [{"subtask_names": ["only"], "per_episode": []}]}}
    _experiment().subtask_gaps(by, {"goal": None, "one step": None}, draws=200)
    out = capsys.readouterr().out  # type: ignore[attr-defined]
    first, second = (line.split() for line in out.splitlines() if line.strip()[:2] in ("1.", "2."))
    assert first[-5:-2] == ["4/8", "1/8", "+37.5%"]  # V-CAGE past the first, Vanilla past it, the gap
    assert second[-5:-2] == ["1/8", "0/8", "+12.5%"]
    assert "one step" not in out  # a single subtask has nothing to add to the success rate


def test_a_ledger_carries_finished_tasks_across_work_folders_and_refuses_mixing(tmp_path: Path) -> None:
    """A finished task's entry survives its work folder: a later run reads it back instead of generating,
    training and evaluating again, the report stage prints the same table from it alone, and an entry
    made by other code or settings is refused rather than put in one table with this run's."""
    ledger = tmp_path / "ledger"
    first = run(tmp_path / "work1", "--ledger", str(ledger))
    entry = json.loads((ledger / "press_the_bell.json").read_text())
    assert entry["task"] == "press the bell" and len(entry["results"]) == 2 and len(entry["curves"]) == 2
    assert entry["settings"]["steps"] == 4 and len(entry["code"]) == 16
    table = first.split("task ")[1].split("\n\n")[0]
    again = run(tmp_path / "work2", "--ledger", str(ledger))  # a new work folder: nothing made again
    assert "from the ledger" in again and "attempts this run" not in again
    assert not (tmp_path / "work2" / "data").exists()
    assert again.split("task ")[1].split("\n\n")[0] == table
    reported = run(tmp_path / "work3", "--stage", "report", "--ledger", str(ledger))
    assert reported.split("task ")[1].split("\n\n")[0] == table and "PARTIAL" not in reported
    assert (ledger / "learning_curves.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    partial = run(tmp_path / "work3", "--stage", "report", "--ledger", str(ledger),
                  "--tasks", "press the bell", "stack the blocks")
    assert "PARTIAL: not in the ledger yet: stack the blocks" in partial
    other = run(tmp_path / "work4", "--ledger", str(ledger), "--lr", "0.002", ok=False)
    assert "made with other settings" in other
    (ledger / "press_the_bell.json").write_text(json.dumps(entry | {"code": "0" * 16}))
    refused = run(tmp_path / "work4", "--ledger", str(ledger), ok=False)
    assert "made with other code" in refused and not (tmp_path / "work4" / "data").exists()
