"""The CLI's one error path: every command is wrapped, and a VcageError is one line and exit code 2."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest
import typer
from typer.testing import CliRunner

from vcage.cli import app
from vcage.cli.errors import MARKER, cli_errors
from vcage.errors import ConfigError

RUN = CliRunner()
VERBS = ["tasks", "plan", "generate", "inspect", "audit", "report", "verify", "backfill", "export", "catalog",
         "scene", "run", "demo", "synthesize", "train", "evaluate"]
GROUPS = ["subtasks"]  # verbs with sub-commands; `vcage --help` lists them after the VERBS


def test_every_command_is_registered_in_order_and_wrapped() -> None:
    names = [c.name for c in app.registered_commands]
    assert names == VERBS
    assert [g.name for g in app.registered_groups] == GROUPS
    commands = list(app.registered_commands) + [c for g in app.registered_groups
                                                for c in g.typer_instance.registered_commands]
    unwrapped = [c.name for c in commands if not getattr(c.callback, MARKER, False)]
    assert unwrapped == []


def test_a_vcage_error_is_one_red_line_and_exit_code_2() -> None:
    result = RUN.invoke(app, ["export", "nowhere", "out.hdf5", "--format", "zip"])
    assert result.exit_code == 2
    assert result.output == "error: unknown export format 'zip'; valid: robomimic\n"
    catalog = RUN.invoke(app, ["catalog", "--category", "nope"])
    assert catalog.exit_code == 2
    assert catalog.output.startswith("error: unknown category 'nope'; valid:")
    assert "Traceback" not in catalog.output and catalog.exception is not None
    assert isinstance(catalog.exception, SystemExit)


def test_the_decorator_keeps_the_signature_and_lets_other_errors_through() -> None:
    demo = typer.Typer()

    @demo.command()
    @cli_errors
    def boom(name: str = typer.Option("x"), crash: bool = typer.Option(False)) -> None:
        if crash:
            raise RuntimeError("a bug, not a user error")
        raise ConfigError(f"bad {name}")

    assert getattr(boom, MARKER) is True and boom.__name__ == "boom"
    result = RUN.invoke(demo, ["--name", "y"])
    assert result.exit_code == 2 and result.output == "error: bad y\n"
    crashed = RUN.invoke(demo, ["--crash"])
    assert crashed.exit_code == 1 and isinstance(crashed.exception, RuntimeError)


@pytest.mark.parametrize("args", [["--help"], []])
def test_python_dash_m_runs_the_cli(args: list[str]) -> None:
    done = subprocess.run([sys.executable, "-m", "vcage.cli", *args], capture_output=True, text=True,
                          timeout=60, env={**os.environ, "COLUMNS": "100"})
    out = done.stdout + done.stderr
    assert "Usage: python -m vcage.cli" in out
    assert all(verb in out for verb in VERBS + GROUPS)
    listed = [line.split()[1] for line in out.splitlines() if line.startswith("│ ") and len(line.split()) > 2
              and line.split()[1] in VERBS + GROUPS]
    assert listed == VERBS + GROUPS
    assert done.returncode == (0 if args else 2)
