"""One synthesis run, stage by stage, writing every artefact and the funnel of what each stage refused.

prompt -> retrieval -> D_scene -> scatter + I_init -> I_goal (image editor) -> matching -> refine
-> settle. Scatter, edit, matching, refine and settle are attempted up to ``attempts`` times with
fresh seeds; a refusal there is recorded in the funnel and the next attempt starts. Refusals of the
prompt or the description end the run at once (no seed changes them). Artefacts are written as they
are made, so what was written before a failure stays.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from vcage.backends import ChatBackend
from vcage.errors import ConfigError, PlacementError, SceneError, VcageError
from vcage.planning.language import tokens as goal_tokens
from vcage.planning.offline import OfflinePlanner
from vcage.scene.instantiate import Instantiator, SceneConfig, SceneInstance
from vcage.scene.layout import LayoutObject, LayoutSpec
from vcage.scene.spec import TableSpec
from vcage.synthesis.asked import read_prompt
from vcage.synthesis.compositor import Compositor
from vcage.synthesis.costs import Problem, Weights
from vcage.synthesis.describe import best_goal, describe
from vcage.synthesis.description import SceneDescription
from vcage.synthesis.editing import ImageEditor, check_goal_image
from vcage.synthesis.errors import PromptError, SynthesisError
from vcage.synthesis.llm_chooser import SHORTLIST, LLMChooser
from vcage.synthesis.llm_describe import LLMDescriber
from vcage.synthesis.matching import MatchReport, match
from vcage.synthesis.perturb import PRESETS
from vcage.synthesis.prompt import check_prompt, noun_phrases
from vcage.synthesis.refine import RefineConfig, refine
from vcage.synthesis.relations_check import Held, relations_held
from vcage.synthesis.retrieval import Retrieval, retriever
from vcage.synthesis.scene_file import FILE as SCENE_FILE
from vcage.synthesis.scene_file import SynthesisRequest, SynthesizedScene, settled_scene, yaw_of
from vcage.synthesis.settle import rests_on, scene_spec, settle
from vcage.synthesis.text import content
from vcage.synthesis.views import render_top


class Sink(Protocol):
    def json(self, name: str, data: Any) -> None: ...
    def png(self, name: str, image: np.ndarray) -> None: ...


class DirectorySink:
    """Writes artefacts into a directory (created on first write)."""

    def __init__(self, root: Path) -> None:
        self.root = Path(root)
        for parent in (self.root, *self.root.parents):  # before any work: the artefacts need a directory
            if parent.exists():
                if not parent.is_dir():
                    raise ConfigError(f"cannot write the artefacts into {self.root}: {parent} is a file; "
                                      "give --out a directory")
                break

    def _path(self, name: str) -> Path:
        path = self.root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        return path

    def json(self, name: str, data: Any) -> None:
        self._path(name).write_text(json.dumps(data, indent=2, default=str))

    def png(self, name: str, image: np.ndarray) -> None:
        from PIL import Image

        Image.fromarray(np.asarray(image, dtype=np.uint8)).save(self._path(name))


class NullSink:
    def json(self, name: str, data: Any) -> None:
        pass

    def png(self, name: str, image: np.ndarray) -> None:
        pass


class MemorySink:
    """Keeps the JSON artefacts in memory (``data`` by name) and drops the images."""

    def __init__(self) -> None:
        self.data: dict[str, Any] = {}

    def json(self, name: str, data: Any) -> None:
        self.data[name] = json.loads(json.dumps(data, default=str))

    def png(self, name: str, image: np.ndarray) -> None:
        pass


@dataclass(frozen=True)
class SynthesisConfig:
    seed: int = 0
    attempts: int = 3
    perturbation: str = "none"  # a preset of vcage.synthesis.perturb for the offline compositor
    lam: float = 1.0
    settle_seconds: float = 0.5
    reach: tuple[float, float, float, float] | None = None  # mount x, y, r_in, r_out

    def __post_init__(self) -> None:
        if self.perturbation not in PRESETS:
            raise SynthesisError(f"unknown perturbation {self.perturbation!r}; valid: {', '.join(PRESETS)}")
        if self.attempts < 1:
            raise SynthesisError(f"attempts must be >= 1, got {self.attempts}")


@dataclass
class SynthesisResult:
    description: SceneDescription
    instance: SceneInstance
    funnel: list[dict[str, Any]] = field(default_factory=list)


def unknown_phrases(text: str) -> tuple[list[str], dict[str, Retrieval]]:
    """Noun phrases that name nothing in the catalog nor a goal word, and every phrase's retrieval."""
    vocab = OfflinePlanner().matcher.vocabulary
    found: dict[str, Retrieval] = {}
    unknown = []
    for phrase in noun_phrases(text):
        if not content(phrase):
            continue
        found[phrase] = retriever().find(phrase, k=3)
        if not found[phrase].found and not set(goal_tokens(phrase)) & vocab:
            unknown.append(phrase)
    return unknown, found


def synthesize(prompt: str, cfg: SynthesisConfig | None = None, sink: Sink | None = None,
               editor: ImageEditor | None = None, llm: ChatBackend | None = None) -> SynthesisResult:
    """The scene ``prompt`` asks for. ``editor`` makes the goal image (default: the offline
    compositor with ``cfg.perturbation``); with ``llm`` a chat model chooses the objects from the
    retrieval shortlist and writes ``D_scene``, else both are done offline."""
    cfg = cfg or SynthesisConfig()
    sink = sink or NullSink()
    funnel: list[dict[str, Any]] = []

    def record(stage: str, status: str, detail: Any = None, attempt: int | None = None) -> None:
        funnel.append({"stage": stage, "status": status, "attempt": attempt, "detail": detail})
        sink.json("funnel.json", funnel)

    try:
        text = check_prompt(prompt)
    except PromptError as exc:
        record("prompt", "rejected", str(exc))
        raise
    scene_hits = retriever().search(text, k=10)
    unknown, phrases = unknown_phrases(text)
    found: dict[str, Any] = {"prompt": scene_hits.to_dict(),
                             "phrases": {p: r.to_dict() for p, r in phrases.items()}, "unknown": unknown}
    sink.json("retrieval.json", found)
    if llm is not None:
        desc = _describe_with_llm(text, llm, scene_hits, phrases, found, sink, record)
    else:
        desc = _describe_offline(text, scene_hits, unknown, sink, record)
    editor = editor or Compositor(PRESETS[cfg.perturbation])
    table = TableSpec()
    last: VcageError | None = None
    for attempt in range(cfg.attempts):
        rng = np.random.default_rng([cfg.seed, attempt])
        try:
            inst = _attempt(desc, cfg, editor, table, rng, sink, record, attempt)
            sink.json(SCENE_FILE, settled_scene(desc, inst, cfg.seed, attempt, editor.name).to_dict())
            return SynthesisResult(desc, inst, funnel)
        except (SynthesisError, SceneError) as exc:
            stage = exc.stage if isinstance(exc, SynthesisError) else (
                "scatter" if isinstance(exc, PlacementError) else "scene")
            record(stage, "rejected", str(exc), attempt)
            last = exc
    raise SynthesisError(f"no valid scene for {text!r} after {cfg.attempts} attempts; last: {last}. "
                         "Try another seed, more attempts, or a prompt with fewer objects")


def synthesized_scene(request: SynthesisRequest, seed: int) -> SynthesizedScene:
    """The settled scene one run for ``request`` with ``seed`` makes (offline: retrieval, description
    and the compositor), without writing its artefacts: what a generation attempt starts from."""
    sink = MemorySink()
    cfg = SynthesisConfig(seed=seed, attempts=request.attempts, perturbation=request.perturbation,
                          lam=request.lam)
    synthesize(request.prompt, cfg, sink)
    return SynthesizedScene.from_dict(sink.data[SCENE_FILE])


Record = Callable[..., None]


def _describe_offline(text: str, scene_hits: Retrieval, unknown: list[str], sink: Sink,
                      record: Record) -> SceneDescription:
    if unknown:
        names = ", ".join(repr(u) for u in unknown)
        msg = (f"the prompt names {names}, which the catalog lacks: name catalog "
               "objects (`vcage catalog` lists them)")
        record("retrieval", "rejected", msg)
        raise PromptError(msg)
    record("retrieval", "ok", {"best": scene_hits.names()[:5], "no_match": scene_hits.no_match})
    try:
        desc, source = describe(text, scene_hits)
    except SynthesisError as exc:
        record("description", "rejected", str(exc))
        raise
    sink.json("scene_description.json", {"source": source.kind, "score": source.score, **desc.model_dump()})
    record("description", "ok", {"source": source.kind, "objects": len(desc.objects),
                                 "relations": [str(r) for r in desc.relations]})
    return desc


def shortlist(scene_hits: Retrieval, phrases: dict[str, Retrieval], text: str) -> list[str]:
    """Candidates for the LLM chooser: the prompt's hits, each noun phrase's, the best goal's objects."""
    names = scene_hits.names() + [n for r in phrases.values() for n in r.names()]
    goal = best_goal(text)
    if goal is not None:
        names += [o.type for o in goal[0].objects]
    return list(dict.fromkeys(names))[:SHORTLIST]


def _describe_with_llm(text: str, llm: ChatBackend, scene_hits: Retrieval, phrases: dict[str, Retrieval],
                       found: dict[str, Any], sink: Sink, record: Record) -> SceneDescription:
    try:
        asked = read_prompt(text)
        choice = LLMChooser(llm).choose(text, shortlist(scene_hits, phrases, text), asked)
    except SynthesisError as exc:
        record("retrieval", "rejected", str(exc))
        raise
    sink.json("retrieval.json", {**found, "llm_choice": choice.to_dict()})
    if not choice.found:
        msg = (f"no suitable object for the prompt: {choice.no_match} (the LLM's answer over the shortlist "
               f"{', '.join(choice.shortlist) or 'none'}); name catalog objects (`vcage catalog` lists them)")
        record("retrieval", "no_match", msg)
        raise PromptError(msg)
    record("retrieval", "ok", {"chosen": [f"{c} x {t}" for t, c in choice.objects],
                               "replies": choice.replies})
    try:
        desc, replies = LLMDescriber(llm).describe(text, choice, asked)
    except SynthesisError as exc:
        record("description", "rejected", str(exc))
        raise
    sink.json("scene_description.json", {"source": "llm", "score": None, "replies": replies,
                                         **desc.model_dump()})
    record("description", "ok", {"source": "llm", "replies": replies, "objects": len(desc.objects),
                                 "relations": [str(r) for r in desc.relations]})
    return desc


def _attempt(desc: SceneDescription, cfg: SynthesisConfig, editor: ImageEditor, table: TableSpec,
             rng: np.random.Generator, sink: Sink, record: Any, attempt: int) -> SceneInstance:
    where = f"attempt-{attempt}/"
    layout = LayoutSpec(objects=tuple(LayoutObject(o.name, o.type, scale=o.scale, color=o.color)
                                      for o in desc.objects), table=table)
    scattered = Instantiator(SceneConfig(settle_seconds=cfg.settle_seconds)).instantiate(layout, rng)
    scattered.require_valid("the scattered objects")
    view, empty = render_top(scattered.world)
    sink.png(where + "I_init.png", view.rgb)
    sink.png(where + "empty_table.png", empty)
    record("scatter", "ok", {"objects": len(view.names)}, attempt)
    edit = editor.edit(view, empty, desc, rng)
    goal = check_goal_image(edit.image, view)
    sink.png(where + "I_goal.png", goal)
    if edit.truth is not None:
        sink.json(where + "goal_truth.json", {"poses": edit.truth, "dropped": edit.dropped, **edit.info})
    else:  # a model's answer: what was asked and what came back, request by request
        sink.json(where + "edit.json", edit.info)
    record("edit", "ok", {"editor": editor.name}, attempt)
    looks = {o.name: (o.type, o.color, o.scale) for o in desc.objects}
    stacked = {frozenset((r.a, r.b)) for r in desc.relations if r.kind in ("on", "inside")}
    report = match(view, empty, goal, looks, stacked)
    sink.json(where + "matches.json", report.to_dict())
    record("matching", "ok" if not report.lost else "partial", {"lost": report.lost}, attempt)
    problem = Problem.build(desc, table, reach=cfg.reach)
    matched = anchors(desc, report)
    result = refine(problem, matched, RefineConfig(weights=Weights(lam=cfg.lam)), rng)
    sink.json(where + "refined_poses.json", result.to_dict())
    record("refine", "ok", {"start": result.start, "mean_displacement_m": round(result.displacement, 4),
                            "seconds": result.to_dict()["seconds"]}, attempt)
    spec = scene_spec(desc, result.poses, table)
    inst = settle(spec, cfg.settle_seconds, desc)
    sink.json("scene_spec.json", inst.spec.to_dict())  # as realised (dropped onto slanted supports)
    held = _relations_after(desc, inst)
    sink.json(where + "relations_held.json", [h.to_dict() for h in held])
    record("settle", "ok", {"stability": inst.stability.reason() if inst.stability else None,
                            "relations_held": f"{sum(h.held for h in held)}/{len(held)}",
                            "not_held": [h.relation for h in held if not h.held]}, attempt)
    return inst


def anchors(desc: SceneDescription, report: MatchReport) -> dict[str, tuple[float, float, float]]:
    """The poses refine starts from and stays near: the matched ones; a lost object that holds a found
    one (a coaster hidden under its cup) is where, and turned as, what it holds was found, not where
    it started."""
    out = {n: (m.xy[0], m.xy[1], m.yaw) for n, m in report.matches.items()}
    for r in desc.relations:
        host, child = report.matches.get(r.b), report.matches.get(r.a)
        if r.kind in ("on", "inside") and host is not None and child is not None and not host.found \
                and child.found:
            out[r.b] = (child.xy[0], child.xy[1], child.yaw)  # held things lie along their holder
    return out


def _relations_after(desc: SceneDescription, inst: SceneInstance) -> list[Held]:
    names = [o.name for o in desc.objects]
    poses = {n: (float(p[0]), float(p[1]), yaw_of(p[3:]))
             for n, p in zip(names, inst.world.object_poses(names), strict=True)}
    resting = {r.a: rests_on(inst.world, r.a, r.b) for r in desc.relations if r.kind in ("on", "inside")}
    return relations_held(desc, poses, resting)
