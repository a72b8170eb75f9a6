"""``vcage audit``: a dataset's label noise and the critic's agreement with the oracle."""

from __future__ import annotations

from pathlib import Path

import typer

from vcage.cli._app import app, console
from vcage.cli.errors import cli_errors


@app.command("audit")
@cli_errors
def audit_cmd(path: Path = typer.Argument(..., help="a dataset directory")) -> None:
    """Label noise of a dataset and the critic's agreement with the oracle, from the attempt log."""
    from vcage.data import DatasetReader
    from vcage.pipeline.audit import audit

    DatasetReader(path)  # refuses what is not a dataset before the attempt log is read
    report = audit(path)
    console.print(report.summary())
