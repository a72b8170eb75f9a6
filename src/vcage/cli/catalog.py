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
    # Fits 80 columns: names, categories, sizes and counts never wrap; the description folds.
    table = Table(caption="size: x, y, z in cm; g/p/f: grasps, placements, functional points",
                  caption_justify="left")
    for header in ("name", "category", "size cm"):
        table.add_column(header, no_wrap=True)
    table.add_column("g/p/f", no_wrap=True, justify="right")
    table.add_column("description", overflow="fold")
    for o in objs:
        table.add_row(o.name, o.category, "x".join(f"{s * 100:.1f}" for s in o.size),
                      f"{len(o.grasps)}/{len(o.placements)}/{len(o.functional_points)}", o.description)
    console.print(table)
    console.print(f"{len(objs)} object types")
