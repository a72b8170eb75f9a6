"""``vcage audit``: a dataset's label noise and the critic's agreement with the oracle."""

from __future__ import annotations

from pathlib import Path

import typer

from vcage.cli._app import app, console
from vcage.cli.errors import cli_errors
from vcage.cli.problems import print_problems


@app.command("audit")
@cli_errors
def audit_cmd(path: Path = typer.Argument(..., help="a dataset directory")) -> None:
    """Label noise of a dataset and the critic's agreement with the oracle, from the attempt log.

    Runs the cheap file checks first and fails, listing the damage, if an episode is damaged.
    """
    from vcage.data import DatasetReader
    from vcage.data.verify import check
    from vcage.pipeline.audit import audit

    report = check(path)  # refuses what is not a dataset before the attempt log is read
    print_problems(report)
    report.raise_if_damaged()
    DatasetReader(path)
    console.print(audit(path).summary())
