"""The table of a dataset's problems, shared by the verbs that check datasets."""

from __future__ import annotations

from typing import TYPE_CHECKING

from rich.table import Table
from rich.text import Text

from vcage.cli._app import console

if TYPE_CHECKING:
    from vcage.data.verify_report import VerifyReport


def print_problems(report: VerifyReport) -> None:
    """One row per problem: the episode(s) it costs, the file, what is wrong (nothing if clean)."""
    if report.ok:
        return
    table = Table(title=f"{len(report.problems)} problem(s) in {report.root}")
    table.add_column("episode", no_wrap=True)
    table.add_column("file", overflow="fold")
    table.add_column("problem", overflow="fold")
    for problem in report.problems:
        table.add_row(Text(problem.where), Text(problem.path), Text(problem.what))
    console.print(table)
