"""``vcage plan``: ground an instruction into a plan without simulating it."""

from __future__ import annotations

import typer

from vcage.cli._app import app, console
from vcage.cli.errors import cli_errors


@app.command("plan")
@cli_errors
def plan_cmd(instruction: str = typer.Argument(..., help="what the robot should do"),
             planner: str = typer.Option("offline", help="offline, or llm (VCAGE_LLM_* env vars)")) -> None:
    """Ground INSTRUCTION into a plan and print it (nothing is simulated)."""
    from vcage.planning import make_planner

    result = make_planner(planner).plan(instruction)
    console.print(result.summary(), markup=False, highlight=False)
