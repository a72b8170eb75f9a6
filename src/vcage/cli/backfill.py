"""``vcage backfill``: add the features newer versions write to a dataset made before them."""

from __future__ import annotations

from pathlib import Path

import typer
from rich.text import Text

from vcage.cli._app import app, console
from vcage.cli.errors import cli_errors


@app.command("backfill")
@cli_errors
def backfill_cmd(path: Path = typer.Argument(..., help="a dataset made by `vcage generate`")) -> None:
    """Add observation.environment_state, subtask_index and action.ee_pose from the stored states."""
    from vcage.pipeline.backfill import BACKFILLED, backfill

    added = backfill(path, progress=lambda done, total: console.print(
        Text(f"data file {done}/{total}"), end="\r"))
    if added:
        console.print(Text(f"{path}: added {', '.join(added)} to every episode"))
    else:
        console.print(Text(f"{path} already has {', '.join(BACKFILLED)}; nothing to add"))
