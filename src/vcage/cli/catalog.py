"""``vcage catalog``: the annotated object catalog."""

from __future__ import annotations

import typer
from rich.table import Table

from vcage.cli._app import app, console
from vcage.cli.errors import cli_errors


@app.command("catalog")
@cli_errors
def list_catalog(category: str = typer.Option(None, help="only this category"),
                 tag: str = typer.Option(None, help="only objects with this tag")) -> None:
    """List the annotated object catalog."""
    from vcage.assets.catalog import CATALOG

    objs = CATALOG.by_category(category) if category else CATALOG.values()
    if tag:
        objs = [o for o in objs if tag in o.tags]
    table = Table("name", "category", "size (cm)", "grasps", "placements", "functional", "description")
    for o in objs:
        table.add_row(o.name, o.category, " x ".join(f"{s * 100:.1f}" for s in o.size),
                      str(len(o.grasps)), str(len(o.placements)), str(len(o.functional_points)),
                      o.description)
    console.print(table)
    console.print(f"{len(objs)} object types")
