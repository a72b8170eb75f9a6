"""The policy experiment's smoke path (``--quick``): the whole loop runs end to end and resumes.

Only that it runs is asserted, never a success figure (two demos and four training steps mean
nothing)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "policy_vcage_vs_vanilla.py"


def run(work: Path) -> str:
    done = subprocess.run([sys.executable, str(SCRIPT), "--work", str(work), "--quick"], capture_output=True,
                          text=True, timeout=600, env={**os.environ, "LP_NUM_THREADS": "1"})
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout


def test_the_quick_experiment_runs_end_to_end_and_resumes(tmp_path: Path) -> None:
    first = run(tmp_path)
    for line in ("Avg SR", "Top-5 (tasks)", "Top-5 (ckpts)", "V-CAGE - Vanilla success gap",
                 "paired bootstrap 95%"):
        assert line in first, first
    results = sorted(p.relative_to(tmp_path).as_posix() for p in (tmp_path / "results").rglob("*.json"))
    assert results == ["results/press_the_bell/vanilla/seed0.json", "results/press_the_bell/vcage/seed0.json"]
    for path in (tmp_path / "results").rglob("*.json"):  # each checkpoint also ran on one training scene
        assert json.loads(path.read_text())["fit"]["episodes"] == 1
    stamps = {p: p.stat().st_mtime_ns for p in (tmp_path / "results").rglob("*.json")}
    second = run(tmp_path)  # everything is done: read back, nothing generated, trained or evaluated again
    assert "(0 attempts this run)" in second
    assert {p: p.stat().st_mtime_ns for p in stamps} == stamps
    assert first.split("task ")[1].split("\n\n")[0] == second.split("task ")[1].split("\n\n")[0]
