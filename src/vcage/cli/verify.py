"""``vcage verify``: check every file of a dataset against its metadata; ``--repair`` drops the damaged
episodes and keeps the intact ones."""

from __future__ import annotations

from pathlib import Path

import typer
from rich.text import Text

from vcage.cli._app import app, console
from vcage.cli.errors import cli_errors
from vcage.cli.problems import print_problems
from vcage.errors import CorruptDatasetError


@app.command("verify")
@cli_errors
def verify_cmd(path: Path = typer.Argument(..., help="a dataset directory"),
               repair: bool = typer.Option(False, "--repair", help="drop the damaged episodes, keep the "
                                           "intact ones (renumbered), render videos again from stored states "
                                           "where only they are damaged, rewrite the metadata; says what it "
                                           "drops and sets it aside in quarantine/")
               ) -> None:
    """Check every episode's files (decoding the videos) and the metadata; fails if anything is damaged."""
    from vcage.data.layout import ATTEMPTS_LOG
    from vcage.data.repair import repair as repair_dataset
    from vcage.data.verify import verify
    from vcage.pipeline.attempt_log import reconcile_dataset
    from vcage.pipeline.rerender import render_from_states

    if repair:
        result = repair_dataset(path, render=render_from_states)
        print_problems(result.before)
        console.print(Text(result.summary()))
        if result.after.ok and reconcile_dataset(path):
            console.print(f"the attempt log ({ATTEMPTS_LOG}) no longer counts the attempts of the dropped "
                          "episodes")
        if not result.after.ok:
            print_problems(result.after)
            raise CorruptDatasetError(f"{path} is still damaged after the repair: {result.after.brief()}")
        return
    report = verify(path)
    print_problems(report)
    if report.ok:
        console.print(Text(report.summary()))
        return
    console.print(Text(report.summary().splitlines()[-1]))
    raise CorruptDatasetError(f"{path} is damaged: {report.brief()}; `vcage verify {path} --repair` drops "
                              "the damaged episodes")
