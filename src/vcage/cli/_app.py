"""The Typer app every verb registers on, and the one console the CLI prints to."""

from __future__ import annotations

import typer
from rich.console import Console

app = typer.Typer(add_completion=False, no_args_is_help=True,
                  help="vcage: verified robot manipulation datasets in MuJoCo.")
console = Console()
