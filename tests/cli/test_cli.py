"""The command line, invoked in-process: the main job end to end, and bad input as clear errors."""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from vcage.cli import app
from vcage.data import DatasetReader

RUN = CliRunner()
SMALL = ["--clutter", "2", "--size", "64"]


def text(result: object) -> str:
    """The output with rich's line wrapping undone."""
    return " ".join(str(getattr(result, "output", "")).split())


def test_tasks_and_plan() -> None:
    listed = RUN.invoke(app, ["tasks"])
    assert listed.exit_code == 0 and "get_ready_for_work" in listed.output
    plan = RUN.invoke(app, ["plan", "put the mouse on the pad, then press the bell"])
    assert plan.exit_code == 0, plan.output
    assert "pick_and_place" in plan.output and "press" in plan.output


def test_plan_refuses_what_it_cannot_ground() -> None:
    result = RUN.invoke(app, ["plan", "fold the laundry"])
    assert result.exit_code == 2
    assert "error:" in result.output and "llm" in result.output  # suggests an LLM planner


def test_generate_inspect_audit_and_a_refused_append(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    made = RUN.invoke(app, ["generate", "press the bell", "--episodes", "1", "--out", str(out), *SMALL])
    assert made.exit_code == 0, made.output
    assert "accepted 1/1 episodes" in text(made) and "per core-hour" in text(made)
    runs = (out / "meta" / "vcage_runs.jsonl").read_text().splitlines()
    assert len(runs) == 1 and json.loads(runs[0])["accepted"] == 1
    assert "holds 1 episodes" in text(made)
    inspected = RUN.invoke(app, ["inspect", str(out)])
    assert inspected.exit_code == 0 and "1 episodes" in text(inspected)
    audited = RUN.invoke(app, ["audit", str(out)])
    assert audited.exit_code == 0, audited.output
    exported = RUN.invoke(app, ["export", str(out), str(tmp_path / "demos.hdf5")])
    assert exported.exit_code == 0 and "1 demos" in text(exported), exported.output
    again = RUN.invoke(app, ["export", str(out), str(tmp_path / "demos.hdf5")])
    assert again.exit_code == 2 and "overwrite" in text(again)
    other = RUN.invoke(app, ["generate", "press the bell", "--episodes", "1", "--out", str(out),
                             "--clutter", "3", "--size", "64"])
    assert other.exit_code == 2 and "error:" in other.output
    assert DatasetReader(out).num_episodes == 1  # the episode already written is kept


def test_bad_options_are_refused_before_any_work(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    for args in (["--workers", "0"], ["--critic", "psychic"], ["--mode", "fast"]):
        result = RUN.invoke(app, ["generate", "press the bell", "--out", str(out), *args])
        assert result.exit_code == 2, (args, result.output)
    assert not (out / "meta").exists()
    missing = RUN.invoke(app, ["audit", str(tmp_path / "nothing")])
    assert missing.exit_code == 2 and "error:" in missing.output
