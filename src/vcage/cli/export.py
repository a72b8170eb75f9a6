"""``vcage export``: a dataset in a policy-learning format (robomimic's HDF5)."""

from __future__ import annotations

from pathlib import Path

import typer

from vcage.cli._app import app, console
from vcage.cli.errors import cli_errors
from vcage.errors import ConfigError


@app.command("export")
@cli_errors
def export_cmd(path: Path = typer.Argument(..., help="a dataset directory"),
               out: Path = typer.Argument(..., help="the file to write, e.g. demos.hdf5"),
               format: str = typer.Option("robomimic", help="robomimic (HDF5)"),
               valid: float = typer.Option(0.1, help="share of episodes in mask/valid"),
               overwrite: bool = typer.Option(False, help="replace OUT if it exists")) -> None:
    """Export a dataset for policy learning: robomimic's HDF5 layout."""
    if format != "robomimic":
        raise ConfigError(f"unknown export format {format!r}; valid: robomimic")
    from vcage.data.robomimic import export_robomimic

    summary = export_robomimic(path, out, valid_fraction=valid, overwrite=overwrite)
    console.print(f"wrote {summary.path}: {summary.demos} demos ({summary.train} train, {summary.valid} "
                  f"valid), {summary.frames} frames; obs keys {', '.join(summary.obs_keys)}")
