"""``vcage report``: one self-contained HTML file showing how a dataset was made, or two compared."""

from __future__ import annotations

from pathlib import Path

import typer

from vcage.cli._app import app, console
from vcage.cli.errors import cli_errors


@app.command("report")
@cli_errors
def report_cmd(
        dataset: Path = typer.Argument(..., help="a dataset directory made by `vcage generate`"),
        dataset_b: Path = typer.Argument(None, help="a second dataset to compare with the first (e.g. "
                                         "Vanilla beside V-CAGE on the same seeds)"),
        out: Path = typer.Option(Path("report.html"), help="the HTML file to write"),
        episodes: int = typer.Option(20, min=0, help="accepted episodes shown with keyframes and a "
                                     "clip (disagreements first); the others are listed"),
        views: int = typer.Option(50, min=0, help="rejected attempts shown with the views the critic "
                                  "judged (disagreements first); every rejection is listed")) -> None:
    """Write an HTML report of a generation run: configuration, funnel, label noise and critic-oracle
    agreement, throughput, every accepted episode (keyframes, verdicts, oracle, clip) and every
    rejected attempt (what the critic saw, and why). With DATASET_B: the two side by side.

    Runs the cheap file checks first and refuses a damaged dataset. The file needs no network or
    server to view: every image is embedded.
    """
    from vcage.report import Limits, build_report

    datasets = [dataset] if dataset_b is None else [dataset, dataset_b]
    report = build_report(datasets, out, Limits(episodes=episodes, views=views))
    for page in report.pages:
        name = f"{page.label}: {page.root}" if page.label else page.root
        console.print(f"{name}: {page.funnel.attempts} attempts, {page.funnel.accepted} accepted, "
                      f"{len(page.rejections)} rejected; label noise {page.audit.label_noise:.1%}",
                      highlight=False)
    console.print(f"wrote {report.path} ({report.size / 1e6:.1f} MB); open it in a browser", highlight=False)
