"""The CLI's tables in an 80-column terminal, and the warning when --workers exceeds the cores."""

from __future__ import annotations

import io
import os
import subprocess
import sys
from pathlib import Path

import pytest
from rich.console import Console
from typer.testing import CliRunner

from vcage.assets.catalog import CATALOG
from vcage.cli import app
from vcage.cli import generate as generate_cli
from vcage.tasks import TASKS

WIDTH = 80


def _vcage(*args: str) -> str:
    done = subprocess.run([sys.executable, "-m", "vcage.cli", *args], capture_output=True, text=True,
                          timeout=120, env={**os.environ, "COLUMNS": str(WIDTH)})
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout


def _fits(text: str) -> None:
    lines = text.splitlines()
    assert lines and max(len(line) for line in lines) <= WIDTH
    assert "…" not in text  # nothing was cut short to fit


def test_catalog_fits_80_columns_and_shows_every_name_whole() -> None:
    text = _vcage("catalog")
    _fits(text)
    cells = {cell.strip() for line in text.splitlines() for cell in line.split("│")}
    assert {o.name for o in CATALOG.values()} <= cells
    assert f"{len(CATALOG.values())} object types" in text


def test_tasks_fit_80_columns_and_show_every_name_whole() -> None:
    text = _vcage("tasks")
    _fits(text)
    cells = {cell.strip() for line in text.splitlines() for cell in line.split("│")}
    assert set(TASKS.names()) <= cells


def test_the_funnel_fits_80_columns_with_long_reasons(monkeypatch: pytest.MonkeyPatch) -> None:
    screen = io.StringIO()
    monkeypatch.setattr(generate_cli, "console", Console(file=screen, width=WIDTH, color_system=None))
    long_name = "a_very_long_object_name_without_any_space_" * 2
    stats = {"stages": {"accepted": 3, "critic": 4, "scene": 2}, "accepted": 3, "episodes_requested": 3,
             "rejections_by_reason": {
                 "critic: subtask N: the mouse is not on the mouse pad: its footprint overlaps the pad by "
                 "N% of its area": 4, f"scene: {long_name} fell over": 2},
             "attempts": 9, "given_up": 0, "label_noise": 0.0, "wall_seconds": 3.2,
             "episodes_per_hour": 100.0, "workers": 1, "episodes_per_core_hour": 100.0,
             "total_over_physics_and_render": 1.3, "dataset_episodes": 3}
    generate_cli.print_funnel(stats, Path("out/dataset"))
    text = screen.getvalue()
    _fits(text)
    joined = "".join(text.replace("│", " ").split())
    assert long_name in joined and "N%ofitsarea" in joined and "critic" in text


def test_more_workers_than_cores_are_warned_about(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0})
    out = tmp_path / "ds"
    args = ["generate", "press the bell", "--episodes", "0", "--total", "--out", str(out)]
    warned = CliRunner().invoke(app, [*args, "--workers", "2"])
    assert warned.exit_code == 0, warned.output
    said = " ".join(warned.output.split())
    assert "warning: --workers 2 exceeds the 1 core(s) available" in said and "--workers 1 or fewer" in said
    quiet = CliRunner().invoke(app, [*args, "--workers", "1"])
    assert quiet.exit_code == 0 and "warning" not in quiet.output
