"""``vcage inspect``: what a dataset holds, episode by episode.

(Named ``inspect_cmd`` so that it is never mistaken for the standard library's ``inspect``.)
"""

from __future__ import annotations

from pathlib import Path

import typer
from rich.table import Table

from vcage.cli._app import app, console
from vcage.cli.errors import cli_errors


@app.command("inspect")
@cli_errors
def inspect_cmd(path: Path = typer.Argument(..., help="a dataset directory")) -> None:
    """Summarise a dataset: episodes, frames, tasks, cameras and per-episode outcomes."""
    from vcage.data import DatasetReader

    reader = DatasetReader(path)
    rows = [(i, reader.episode_meta(i), reader.extras(i)) for i in range(reader.num_episodes)]
    console.print(f"{path}: {reader.num_episodes} episodes, {reader.total_frames} frames at "
                  f"{reader.fps} fps; "
                  f"cameras {', '.join(f'{k} {w}x{h}' for k, (h, w) in reader.cameras.items())}")
    table = Table("episode", "frames", "seed", "subtasks", "oracle", "task")
    for i, meta, extras in rows:
        table.add_row(str(i), str(meta.get("length")), str(extras.get("seed")),
                      str(len(extras.get("subtasks", []))),
                      "ok" if extras.get("oracle_success") else "[red]failed[/red]",
                      str(meta.get("tasks", [""])[0]))
    console.print(table)
