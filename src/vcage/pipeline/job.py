"""A run's job: its plan, and the configuration that records where its scenes come from.

The scene source is one choice: the plan's own layout (the default: the planner's plan laid out in
the work area), a synthesized scene file (``GenerateConfig.synthesized``), a prompt synthesized into
a new scene for every attempt (``synthesis``), or a chain of verified subtasks from a subtask
database (``chain``: its plan and its scene); ``GenerateConfig.scene_source`` names it, and the
configuration refuses two at once. :func:`build_job` resolves the choice once, from the
configuration and what a caller adds on top of it (:class:`SceneSource`: the command line's
``--scene``, ``--synthesize``, ``--subtasks``), grounds the plan on the scene, and returns the
configuration that records the choice, so that a dataset's stored configuration rebuilds the same
job.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from vcage.errors import ConfigError
from vcage.pipeline.config import GenerateConfig
from vcage.planning import make_planner
from vcage.planning.schema import Plan


@dataclass(frozen=True)
class SceneSource:
    """A scene source asked for on top of the configuration (none: the configuration's own)."""

    scene_file: Path | None = None  # a synthesized scene (``vcage synthesize ... --out DIR``)
    synthesize: str | None = None  # a prompt to synthesize a new scene from for every attempt
    subtasks: Path | None = None  # a subtask database: a chain of its verified subtasks is the plan
    chain: int = 3  # with ``subtasks``: subtasks in the chain
    subtask_scene: str | None = None  # with ``subtasks``: the scene id to chain in


@dataclass(frozen=True)
class Job:
    instruction: str
    plan: Plan
    cfg: GenerateConfig  # records the scene source the plan is grounded on


def build_job(cfg: GenerateConfig, instruction: str | None, source: SceneSource = SceneSource()) -> Job:
    """The plan of ``instruction`` (or of a subtask chain) grounded on its scene source; a
    :class:`ConfigError` when the sources given contradict each other or none names a task."""
    if source.subtasks is not None or cfg.scene_source == "chain":
        if instruction is not None or source.scene_file is not None or source.synthesize is not None:
            raise ConfigError("--subtasks composes its own plan and scene: give no INSTRUCTION, no "
                              "--scene and no --synthesize")
        plan, cfg = _subtask_chain(cfg, source)
        return Job(plan.instruction, plan, cfg)
    if instruction is None:
        raise ConfigError("give an INSTRUCTION (e.g. 'get ready for work'), or --subtasks DB to run a chain "
                          "of verified subtasks")
    plan = make_planner(cfg.planner).plan(instruction)
    if source.synthesize is not None or cfg.scene_source == "synthesis":
        if source.scene_file is not None:
            raise ConfigError("--synthesize makes a new scene for every attempt: give no --scene")
        plan, cfg = _scene_per_attempt(plan, cfg, source.synthesize)
    elif source.scene_file is not None or cfg.scene_source == "scene":
        plan, cfg = _synthesized_scene(plan, cfg, source.scene_file)
    return Job(instruction, plan, cfg)


def _synthesized_scene(plan: Plan, cfg: GenerateConfig, path: Path | None) -> tuple[Plan, GenerateConfig]:
    """The plan bound to the synthesized scene in ``path`` (else the one ``cfg`` already holds, e.g.
    from a dataset's configuration), and ``cfg`` holding that scene."""
    from vcage.synthesis.scene_file import ground_plan, load_scene

    synthesized = load_scene(path) if path is not None else cfg.synthesized
    assert synthesized is not None
    plan, synthesized = ground_plan(plan, synthesized)
    return plan, replace(cfg, synthesized=synthesized)


def _scene_per_attempt(plan: Plan, cfg: GenerateConfig, prompt: str | None) -> tuple[Plan, GenerateConfig]:
    """The plan grounded on the scene synthesized from ``prompt`` (else from the prompt ``cfg``
    records) with the run seed, and ``cfg`` asking for a new scene per attempt."""
    from vcage.synthesis.driver import synthesized_scene
    from vcage.synthesis.scene_file import SynthesisRequest, ground_plan

    request = SynthesisRequest(prompt) if prompt is not None else cfg.synthesis
    assert request is not None
    plan, _ = ground_plan(plan, synthesized_scene(request, cfg.seed))
    return plan, replace(cfg, synthesis=request, synthesized=None)


def _subtask_chain(cfg: GenerateConfig, source: SceneSource) -> tuple[Plan, GenerateConfig]:
    """A chain of verified subtasks of the database drawn with the run seed (else the chain ``cfg``
    already records, rebuilt from its ids), and ``cfg`` recording it and its scene."""
    from vcage.subtasks.chains import compose, rebuild
    from vcage.subtasks.store import SubtaskStore

    if source.subtasks is not None:
        with SubtaskStore(source.subtasks, readonly=True) as store:
            composed = compose(store, source.chain, cfg.seed, source.subtask_scene)
    else:
        assert cfg.chain is not None
        with SubtaskStore(cfg.chain.db, readonly=True) as store:
            composed = rebuild(store, cfg.chain)
    return composed.plan, replace(cfg, synthesized=composed.scene, chain=composed.provenance, synthesis=None)
