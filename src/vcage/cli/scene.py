"""``vcage scene``: one cluttered table, checked in physics and rendered from the top."""

from __future__ import annotations

import json
from pathlib import Path

import typer

from vcage.cli._app import app, console
from vcage.cli.errors import cli_errors

SETTLE_SECONDS = 1.0  # a whole second: a cluttered table shows any instability by then


@app.command("scene")
@cli_errors
def scene(objects: int = typer.Option(20, min=0, help="catalog objects to place as clutter"),
          method: str = typer.Option("context", help="placement method: context, naive, rejection"),
          seed: int = typer.Option(0, min=0), out: Path = typer.Option(Path("out/scene")),
          width: int = typer.Option(640), height: int = typer.Option(480)) -> None:
    """Instantiate a cluttered table, check it in physics, and render it from the top."""
    import numpy as np
    from PIL import Image

    from vcage.scene.instantiate import Instantiator, SceneConfig
    from vcage.scene.layout import Distractors, LayoutSpec
    from vcage.sim.render import contact_sheet
    from vcage.skills.reachability import reach_map

    instantiator = Instantiator(SceneConfig(method, objects, settle_seconds=SETTLE_SECONDS),
                                reach=reach_map())
    scene = instantiator.instantiate(LayoutSpec(distractors=Distractors(objects)),
                                     np.random.default_rng(seed))
    report, stats = scene.stability, scene.placement
    assert report is not None
    out.mkdir(parents=True, exist_ok=True)
    top = contact_sheet(scene.world, [None], ["top"], width, height)  # the table as it settled
    Image.fromarray(top).save(out / f"{method}_{objects}_seed{seed}.png")
    secs = np.asarray(stats.seconds) * 1000
    (out / f"{method}_{objects}_seed{seed}.json").write_text(json.dumps(
        {"scene": scene.spec.to_dict(), "stability": report.reason(),
         "ms_per_object": secs.tolist(), "backtracks": stats.backtracks}, indent=2))
    verdict = "[green]valid[/green]" if report.ok else f"[red]invalid[/red]: {report.reason()}"
    console.print(f"{method}: placed {stats.placed} objects in {secs.sum():.1f} ms "
                  f"(median {np.median(secs) if secs.size else 0:.2f} ms/object, "
                  f"{stats.backtracks} backtracks, {stats.coverage:.0%} of the table "
                  f"covered); after settling: {verdict}")
    console.print(f"image and scene spec in {out}/")
