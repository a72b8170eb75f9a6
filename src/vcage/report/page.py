"""What the page shows of one dataset, assembled from its evidence (no HTML here)."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, replace
from typing import Any

from vcage.pipeline import critic_views
from vcage.pipeline.audit import AuditReport
from vcage.pipeline.stage import Stage
from vcage.report.charts import funnel_chart, phase_chart
from vcage.report.dataset import RunEvidence
from vcage.report.episodes import EpisodeEvidence, episode_evidence
from vcage.report.funnel import FunnelCounts, count
from vcage.report.media import data_uri, svg_uri
from vcage.report.rejections import Rejection, rejections
from vcage.report.runs import RunTiming, run_timing, total

# the configuration fields shown at the top of a dataset's overview (the rest under "full configuration")
HEADLINE = ("critic.name", "planner.name", "scene.placement", "scene.clutter", "seed", "max_attempts",
            "render.cameras", "render.size")


@dataclass(frozen=True)
class Limits:
    """How much is embedded: keyframes and clips of ``episodes`` episodes, the critic's views of
    ``views`` rejected attempts (disagreements first); everything else is still listed."""

    episodes: int = 20
    views: int = 50


@dataclass(frozen=True)
class DatasetPage:
    key: str  # for element ids: "a", "b"
    label: str  # "A", "B" in a comparison, else ""
    root: str
    instruction: str
    headline: list[tuple[str, str]]
    config: list[tuple[str, str]]
    settings: dict[str, str]  # the same, by key
    subtasks: list[dict[str, Any]]  # of the plan
    episodes_held: int
    fps: int
    funnel: FunnelCounts
    funnel_chart: str  # data URI
    audit: AuditReport
    runs: list[RunTiming]
    runs_total: RunTiming
    phase_chart: str | None
    episodes: list[EpisodeEvidence]  # disagreements first, then by index
    episodes_with_media: int
    rejections: list[Rejection]  # disagreements first, then in log order
    views_shown: int


def flatten(tree: Any, prefix: str = "") -> Iterator[tuple[str, str]]:
    """(dotted key, shown value) of every leaf of a configuration tree."""
    if isinstance(tree, dict) and tree:
        for key, value in tree.items():
            yield from flatten(value, f"{prefix}.{key}" if prefix else str(key))
    elif isinstance(tree, list):
        yield prefix, " x ".join(map(str, tree)) if prefix.endswith("size") else ", ".join(map(str, tree))
    else:
        yield prefix, "none" if tree is None or tree == {} else str(tree)


def dataset_page(evidence: RunEvidence, key: str, label: str, limits: Limits) -> DatasetPage:
    reader = evidence.reader
    funnel = count(evidence.attempts)
    runs = [run_timing(r) for r in evidence.runs]
    config = list(flatten(evidence.config))
    shown = dict(config)
    episodes = [episode_evidence(reader, i, media=False) for i in range(len(reader))]
    episodes.sort(key=lambda e: not e.disagrees)  # stable: index order within each group
    chosen = {e.index for e in episodes[:limits.episodes]}
    episodes = [episode_evidence(reader, e.index, media=True) if e.index in chosen else e for e in episodes]
    rejected, views = _with_views(evidence, rejections(evidence.attempts), limits.views)
    return DatasetPage(
        key=key, label=label, root=str(evidence.root), instruction=str(evidence.plan.get("instruction", "")),
        headline=[(k, shown[k]) for k in HEADLINE if k in shown], config=config, settings=shown,
        subtasks=list(evidence.plan.get("subtasks", [])), episodes_held=len(reader), fps=reader.fps,
        funnel=funnel, funnel_chart=svg_uri(funnel_chart(funnel)), audit=evidence.audit, runs=runs,
        runs_total=total(runs), phase_chart=svg_uri(phase_chart(runs)) if runs else None,
        episodes=episodes, episodes_with_media=len(chosen), rejections=rejected, views_shown=views)


def _with_views(evidence: RunEvidence, rejected: list[Rejection], limit: int) -> tuple[list[Rejection], int]:
    """``rejected`` with the critic's views of the first ``limit`` that have one; and how many."""
    out, shown = [], 0
    for rej in rejected:
        stored = critic_views.path(evidence.root, rej.sample, rej.attempt).is_file()
        png = critic_views.load(evidence.root, rej.sample, rej.attempt) if stored and shown < limit else None
        if png is not None:
            out.append(replace(rej, view=data_uri(png, "image/png")))
            shown += 1
        elif stored:
            out.append(replace(rej, view_note=f"view not embedded (more than {limit} views; raise --views)"))
        elif rej.stage == Stage.CRITIC:
            out.append(replace(rej, view_note="no view stored: this critic judges without images (the "
                                             "oracle), or the dataset was made before views were kept"))
        else:
            out.append(replace(rej, view_note=f"rejected at {rej.stage}, not by the critic: no view"))
    return out, shown
