"""``vcage synthesize``: a prompt to a settled, arranged scene, with every intermediate artefact."""

from __future__ import annotations

from pathlib import Path

import typer

from vcage.cli._app import app, console
from vcage.cli.errors import cli_errors


@app.command("synthesize")
@cli_errors
def synthesize(prompt: str = typer.Argument(..., help="the scene, e.g. 'organize the breakfast table'"),
               out: Path = typer.Option(Path("out/synthesis"), help="directory for the artefacts"),
               seed: int = typer.Option(0), attempts: int = typer.Option(3, min=1),
               perturb: str = typer.Option("none", help="realism perturbation of the offline goal image: "
                                           "none, shift, color, blur, jpeg, drop, realistic"),
               lam: float = typer.Option(1.0, help="lambda: weight of the semantic cost in the refine step"),
               reach: bool = typer.Option(True, help="keep objects within the arm's top-down reach")) -> None:
    """Retrieve objects, describe the scene, render, edit, match, refine and settle it (stages 1-4)."""
    from vcage.scene.spec import TableSpec
    from vcage.synthesis.driver import DirectorySink, SynthesisConfig
    from vcage.synthesis.driver import synthesize as run

    bounds = None
    if reach:
        from vcage.skills.reachability import reach_map

        rmap = reach_map()
        r_in, r_out = rmap.interval(TableSpec().height)
        bounds = (rmap.mount[0], rmap.mount[1], r_in, r_out)
    cfg = SynthesisConfig(seed=seed, attempts=attempts, perturbation=perturb, lam=lam, reach=bounds)
    result = run(prompt, cfg, DirectorySink(out))
    desc = result.description
    console.print(f"scene of {len(desc.objects)} objects "
                  f"({', '.join(o.name for o in desc.objects)}); relations: "
                  f"{', '.join(str(r) for r in desc.relations) or 'none'}")
    rejected = [f for f in result.funnel if f["status"] == "rejected"]
    tries = 1 + max((f["attempt"] or 0) for f in result.funnel)
    console.print(f"settled and valid after {tries} attempt(s); "
                  f"{len(rejected)} rejection(s); artefacts and funnel.json in {out}/")
