"""The report's charts, drawn with matplotlib (Agg, no display) as SVG text.

Figures are built with the object API (no pyplot state), and the SVG is made reproducible: no date,
fixed element ids.
"""

from __future__ import annotations

import io
import textwrap
from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")  # before anything draws: no display is needed, none is touched

from matplotlib.axes import Axes
from matplotlib.figure import Figure

from vcage.pipeline.stage import Stage
from vcage.report.funnel import FunnelCounts
from vcage.report.runs import PHASES, RunTiming

ACCEPTED, REJECTED = "#2e7d32", "#c62828"
PHASE_COLOURS = {"physics": "#1565c0", "render": "#ef6c00", "other": "#9e9e9e"}
SHOWN_REASONS = 8


def to_svg(figure: Figure) -> str:
    buffer = io.StringIO()
    with matplotlib.rc_context({"svg.hashsalt": "vcage-report", "svg.fonttype": "path"}):
        figure.savefig(buffer, format="svg", metadata={"Date": None}, bbox_inches="tight")
    return buffer.getvalue()


def funnel_chart(funnel: FunnelCounts) -> str:
    """Attempts by the stage they ended at; beside it, the most frequent rejection reasons."""
    reasons = funnel.reasons[:SHOWN_REASONS]
    rows = max(len(funnel.stages), len(reasons))
    figure = Figure(figsize=(9.0 if reasons else 4.5, 0.8 + 0.28 * rows))
    axes = figure.subplots(1, 2 if reasons else 1, squeeze=False)[0]
    stages = list(funnel.stages)
    values = [funnel.stages[s] for s in stages]
    colours = [ACCEPTED if s == Stage.ACCEPTED else REJECTED for s in stages]
    _bars(axes[0], stages, values, colours, "attempts by stage", rows)
    if reasons:
        labels = [textwrap.shorten(f"{r.stage}: {r.reason}", 48, placeholder="…") for r in reasons]
        _bars(axes[1], labels, [r.attempts for r in reasons], [REJECTED] * len(reasons),
              "rejections by reason", rows)
    figure.tight_layout()
    return to_svg(figure)


def phase_chart(runs: Sequence[RunTiming]) -> str:
    """Core time of each run split into physics, rendering and the rest (stacked bars)."""
    figure = Figure(figsize=(6.5, 0.7 + 0.35 * len(runs)))
    ax = figure.subplots()
    labels = [f"run {i + 1}" for i in range(len(runs))]
    left = [0.0] * len(runs)
    for phase in PHASES:
        widths = [r.phase(phase) for r in runs]
        ax.barh(labels, widths, left=left, color=PHASE_COLOURS[phase], label=phase)
        left = [a + b for a, b in zip(left, widths, strict=True)]
    ax.invert_yaxis()
    ax.set_xlabel("core seconds")
    ax.legend(loc="lower right", fontsize=8, frameon=False, ncols=len(PHASES))
    ax.spines[["top", "right"]].set_visible(False)
    figure.tight_layout()
    return to_svg(figure)


def _bars(ax: Axes, labels: list[str], values: list[int], colours: list[str], title: str, rows: int) -> None:
    """Horizontal bars, top to bottom, ``rows`` high (panels side by side get bars of one thickness)."""
    bars = ax.barh(range(len(labels)), values, height=0.6, color=colours)
    ax.set_yticks(range(len(labels)), labels)
    ax.bar_label(bars, padding=2, fontsize=8)
    ax.set_ylim(rows - 0.5, -0.5)
    ax.set_title(title, fontsize=10, loc="left")
    ax.tick_params(labelsize=8)
    ax.set_xlim(0, max([*values, 1]) * 1.15)
    ax.spines[["top", "right"]].set_visible(False)
