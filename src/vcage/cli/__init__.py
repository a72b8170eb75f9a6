"""The ``vcage`` command line: one module per verb. Only this package configures output and exits.

Each verb module registers its command on :data:`app` when imported, so the imports below fix the
order ``vcage --help`` lists the commands in. Commands import their heavy dependencies lazily.
"""

from __future__ import annotations

from vcage.cli._app import app, console

# The order of these imports is the order of the commands in `vcage --help`.
# isort: off
from vcage.cli import tasks, plan, generate, inspect_cmd, audit, report, verify  # noqa: F401
from vcage.cli import backfill, export, catalog, scene, run  # noqa: F401
from vcage.cli import synthesize  # noqa: F401
from vcage.cli import subtasks  # noqa: F401
from vcage.cli import train, evaluate  # noqa: F401
# isort: on


def main() -> None:
    app()


__all__ = ["app", "console", "main"]
