"""``vcage inspect``: what a dataset holds, episode by episode, and whether its files are intact.

(Named ``inspect_cmd`` so that it is never mistaken for the standard library's ``inspect``.)
"""

from __future__ import annotations

from pathlib import Path

import typer
from rich.table import Table
from rich.text import Text

from vcage.cli._app import app, console
from vcage.cli.errors import cli_errors
from vcage.cli.problems import print_problems
from vcage.errors import CorruptDatasetError


@app.command("inspect")
@cli_errors
def inspect_cmd(path: Path = typer.Argument(..., help="a dataset directory")) -> None:
    """Summarise a dataset: episodes, frames, tasks, cameras, per-episode outcomes and damaged files.

    Runs the cheap file checks (no video is decoded; ``vcage verify`` decodes them) and fails if an
    episode is damaged.
    """
    from vcage.data import DatasetReader
    from vcage.data.verify import check

    report = check(path)
    try:
        reader = DatasetReader(path)
    except CorruptDatasetError:
        print_problems(report)
        report.raise_if_damaged()
        raise
    damaged = set(report.damaged)
    console.print(f"{path}: {reader.num_episodes} episodes, {reader.total_frames} frames at "
                  f"{reader.fps} fps; "
                  f"cameras {', '.join(f'{k} {w}x{h}' for k, (h, w) in reader.cameras.items())}")
    table = Table("episode", "frames", "seed", "subtasks", "oracle", "files", "task")
    for i in range(reader.num_episodes):
        meta = reader.episode_meta(i)
        try:
            extras = reader.extras(i)
        except CorruptDatasetError:
            extras = {}
        table.add_row(str(i), str(meta.get("length")), str(extras.get("seed")),
                      str(len(extras.get("subtasks", []))),
                      "ok" if extras.get("oracle_success") else "[red]failed[/red]",
                      "[red]damaged[/red]" if i in damaged else "ok",
                      Text(str((meta.get("tasks") or [""])[0])))
    console.print(table)
    print_problems(report)
    report.raise_if_damaged()
