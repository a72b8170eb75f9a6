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
               seed: int = typer.Option(0, min=0), attempts: int = typer.Option(3, min=1),
               perturb: str = typer.Option("none", help="realism perturbation of the offline goal image: "
                                           "none, shift, color, blur, jpeg, drop, turn, realistic"),
               lam: float = typer.Option(1.0, help="lambda: weight of the semantic cost in the refine step"),
               reach: bool = typer.Option(True, help="keep objects within the arm's top-down reach"),
               editor: str = typer.Option("compositor", help="goal images: compositor (offline) or model "
                                          "(an image model; endpoint from --image-* or $VCAGE_IMAGE_*)"),
               image_provider: str = typer.Option(None, help="gemini (generateContent) or openai (any "
                                                  "OpenAI-compatible /images/edits)"),
               image_url: str = typer.Option(None, help="image model's base URL "
                                             "(else $VCAGE_IMAGE_BASE_URL)"),
               image_model: str = typer.Option(None, help="image model (else $VCAGE_IMAGE_MODEL)"),
               image_field: str = typer.Option("image[]", help="openai: multipart field, image[] or image"),
               resamples: int = typer.Option(2, help="new requests after a blocked or imageless answer"),
               llm: bool = typer.Option(False, help="an LLM chooses the objects from the retrieval "
                                        "shortlist and writes the scene description ($VCAGE_LLM_*)"),
               llm_provider: str = typer.Option(None, help="openai (any compatible server) or gemini"),
               llm_url: str = typer.Option(None, help="LLM's base URL (else $VCAGE_LLM_BASE_URL)"),
               llm_model: str = typer.Option(None, help="LLM (else $VCAGE_LLM_MODEL)")) -> None:
    """Retrieve objects, describe the scene, render, edit, match, refine and settle it (stages 1-4)."""
    from dataclasses import replace

    from vcage.backends import BackendConfig, connect
    from vcage.scene.spec import TableSpec
    from vcage.synthesis.driver import DirectorySink, SynthesisConfig
    from vcage.synthesis.driver import synthesize as run
    from vcage.synthesis.editors import EditorConfig, make_editor
    from vcage.synthesis.model_editor import ModelEditorConfig

    if editor == "model":
        editor_cfg = EditorConfig.from_env(provider=image_provider, base_url=image_url, model=image_model)
        editor_cfg = replace(editor_cfg, image_field=image_field,
                             model=ModelEditorConfig(resamples=resamples))
    else:
        editor_cfg = EditorConfig(name=editor, perturbation=perturb)
    chat = None
    if llm:
        given = {k: v for k, v in {"provider": llm_provider, "base_url": llm_url, "model": llm_model}.items()
                 if v is not None}
        chat = connect(BackendConfig.from_env("VCAGE_LLM", None, **given))

    bounds = None
    if reach:
        from vcage.skills.reachability import reach_map

        rmap = reach_map()
        r_in, r_out = rmap.interval(TableSpec().height)
        bounds = (rmap.mount[0], rmap.mount[1], r_in, r_out)
    cfg = SynthesisConfig(seed=seed, attempts=attempts, perturbation=perturb, lam=lam, reach=bounds)
    image_editor = make_editor(editor_cfg)
    try:
        for endpoint in (getattr(image_editor, "backend", None), chat):
            if endpoint is not None:
                endpoint.preflight()  # before anything is written: an unreachable model fails here
        result = run(prompt, cfg, DirectorySink(out), editor=image_editor, llm=chat)
    finally:
        for closing in (getattr(image_editor, "backend", None), chat):
            if closing is not None:
                closing.close()
    desc = result.description
    console.print(f"scene of {len(desc.objects)} objects "
                  f"({', '.join(o.name for o in desc.objects)}); relations: "
                  f"{', '.join(str(r) for r in desc.relations) or 'none'}")
    rejected = [f for f in result.funnel if f["status"] == "rejected"]
    tries = 1 + max((f["attempt"] or 0) for f in result.funnel)
    console.print(f"settled and valid after {tries} attempt(s); "
                  f"{len(rejected)} rejection(s); artefacts and funnel.json in {out}/")
