"""``vcage tasks``: the atomic tasks and long-horizon goals."""

from __future__ import annotations

from rich.table import Table

from vcage.cli._app import app, console
from vcage.cli.errors import cli_errors
from vcage.config import Randomization


@app.command("tasks")
@cli_errors
def list_tasks() -> None:
    """List the atomic tasks with an example instruction."""
    import numpy as np

    from vcage.tasks import TASKS, make_task, place_scene

    table = Table("task", "example instruction")
    for name in TASKS.names():
        task = make_task(name)
        place_scene(task, np.random.default_rng(0), Randomization.off())  # the words need the scene
        table.add_row(name, task.instruction())
    console.print(table)
    from vcage.planning.goals import GOALS

    goals = Table("long-horizon goal", "subtasks", "example instructions")
    for g in GOALS:
        goals.add_row(g.name, str(len(g.subtasks)), "; ".join(g.phrasings[:2]))
    console.print(goals)
    console.print("explicit sequences also work, e.g. 'put the mouse on the mouse pad, then press the bell'")
