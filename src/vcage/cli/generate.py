"""``vcage generate``: a verified dataset for an instruction, and the funnel of its attempts."""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer
from rich.table import Table
from rich.text import Text

from vcage.cli._app import app, console
from vcage.cli.errors import EXIT_PARTIAL, cli_errors, exit_code, fail
from vcage.errors import BackendError, ConfigError

if TYPE_CHECKING:
    from vcage.pipeline.config import GenerateConfig


@app.command("generate")
@cli_errors
def generate_cmd(
        instruction: str = typer.Argument(None, help="e.g. 'get ready for work' (none with --subtasks)"),
        episodes: int = typer.Option(3, min=0, help="accepted episodes to add (with --total: the "
                                     "episodes the dataset must hold)"),
        total: bool = typer.Option(False, help="make the dataset hold --episodes episodes in all: "
                                   "completes an interrupted or partial run"),
        out: Path = typer.Option(Path("out/dataset"), help="dataset directory (LeRobot v3 layout)"),
        config: Path = typer.Option(None, help="a JSON configuration tree to start from (e.g. the "
                                    "\"generate\" part of a dataset's meta/vcage.json); options "
                                    "given here override it"),
        mode: str = typer.Option("vcage", help="preset: vcage, or vanilla (naive placement, no "
                                 "scene check, no critic)"),
        planner: str = typer.Option(None, help="offline (default) or llm"),
        planner_model: str = typer.Option(None, help="LLM planner's model (else $VCAGE_LLM_MODEL)"),
        planner_url: str = typer.Option(None, help="LLM planner's base URL (else $VCAGE_LLM_BASE_URL)"),
        planner_provider: str = typer.Option(None, help="openai (any compatible server) or gemini"),
        planner_timeout: float = typer.Option(None, help="seconds per LLM request (default 30)"),
        planner_retries: int = typer.Option(None, help="retries of a failed LLM request (default 3)"),
        planner_preflight: bool = typer.Option(None, "--planner-preflight/--no-planner-preflight",
                                               help="check the LLM endpoint before any work (default on; off "
                                               "for servers that list no models; else $VCAGE_LLM_PREFLIGHT)"),
        critic: str = typer.Option(None, help="critic that verifies each subtask: image (default, "
                                   "offline), vlm, oracle"),
        critic_model: str = typer.Option(None, help="VLM critic's model (else $VCAGE_VLM_MODEL)"),
        critic_url: str = typer.Option(None, help="VLM critic's base URL (else $VCAGE_VLM_BASE_URL)"),
        critic_provider: str = typer.Option(None, help="openai (any compatible server) or gemini"),
        critic_timeout: float = typer.Option(None, help="seconds per VLM request (default 30)"),
        critic_retries: int = typer.Option(None, help="retries of a failed VLM request (default 3)"),
        critic_preflight: bool = typer.Option(None, "--critic-preflight/--no-critic-preflight",
                                              help="check the VLM endpoint before any work (default on; off "
                                              "for servers that list no models; else $VCAGE_VLM_PREFLIGHT)"),
        votes: int = typer.Option(None, help="VLM critic: answers asked per subtask (default 1)"),
        vote_rule: str = typer.Option(None, help="VLM critic: majority (default) or all"),
        placement: str = typer.Option(None, help="context (default), naive or rejection"),
        clutter: int = typer.Option(None, help="distractors per scene (default 4)"),
        seed: int = typer.Option(None, help="run seed (default 0)"),
        max_attempts: int = typer.Option(None, help="attempts per episode (default 10)"),
        cameras: str = typer.Option(None, help="comma-separated cameras to record (default "
                                    "front,panda/wrist)"),
        size: int = typer.Option(None, help="video width and height (even; default 128)"),
        workers: int = typer.Option(None, help="episodes attempted at once (one core each); the "
                                    "dataset is the same for any number"),
        scene: Path = typer.Option(None, help="a synthesized scene (`vcage synthesize ... --out DIR`: "
                                   "DIR or DIR/scene.json) the episodes start from; the dataset "
                                   "records it and where it came from"),
        synthesize: str = typer.Option(None, help="a prompt (e.g. 'organize the breakfast table') to "
                                       "synthesize a new scene from for every attempt, offline, seeded by "
                                       "the attempt; the plan is grounded on its objects"),
        subtasks: Path = typer.Option(None, help="a subtask database (`vcage subtasks verify`): run a "
                                      "chain of its verified subtasks instead of an instruction"),
        chain: int = typer.Option(3, min=1, max=12, help="with --subtasks: subtasks in the chain"),
        subtask_scene: str = typer.Option(None, help="with --subtasks: the scene id to chain in "
                                          "(default: one drawn with the run seed)"),
        executor: str = typer.Option(None, help="local (this machine: processes) or ray"),
        address: str = typer.Option(None, help="with --executor ray: a running cluster's address "
                                    "(e.g. auto); default: start Ray locally")) -> None:
    """Generate a verified dataset for INSTRUCTION (or for a chain of verified subtasks with
    --subtasks); prints the funnel (also appended to meta/vcage_runs.jsonl). Exit code 3 when fewer
    episodes were accepted than asked."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from vcage.pipeline.generate import generate
    from vcage.pipeline.job import SceneSource, build_job

    cfg = build_config(config, mode, {
        ("planner", "name"): planner, ("critic", "name"): critic, ("critic", "votes"): votes,
        ("critic", "rule"): vote_rule, ("scene", "placement"): placement, ("scene", "clutter"): clutter,
        ("seed",): seed, ("max_attempts",): max_attempts,
        ("render", "cameras"): tuple(c.strip() for c in cameras.split(",") if c.strip()) if cameras else None,
        ("render", "size"): (size, size) if size is not None else None,
        ("executor", "name"): executor, ("executor", "workers"): workers, ("executor", "address"): address,
    }, {"planner": ("VCAGE_LLM", {"provider": planner_provider, "base_url": planner_url,
                                  "model": planner_model, "timeout": planner_timeout,
                                  "max_retries": planner_retries, "preflight": planner_preflight}),
        "critic": ("VCAGE_VLM", {"provider": critic_provider, "base_url": critic_url, "model": critic_model,
                                 "timeout": critic_timeout, "max_retries": critic_retries,
                                 "preflight": critic_preflight})})
    cfg = cfg.resolved()
    warn_if_oversubscribed(cfg.executor.name, cfg.executor.workers)
    built = build_job(cfg, instruction, SceneSource(scene, synthesize, subtasks, chain, subtask_scene))
    instruction, plan, cfg = built.instruction, built.plan, built.cfg  # planned before any progress shows
    bar = Progress(TextColumn("{task.description}"), BarColumn(),
                   TextColumn("{task.completed}/{task.total}"), TimeElapsedColumn(), console=console)
    job = None

    def update(f: object) -> None:
        """Shown from the first call on: once everything was checked and the episodes start."""
        from vcage.pipeline.generate import Funnel

        nonlocal job
        assert isinstance(f, Funnel)
        if job is None:
            bar.start()
            job = bar.add_task("episodes", total=f.episodes_requested)
        bar.update(job, completed=f.accepted + f.given_up,
                   description=f"episodes (attempts {f.attempts}, accepted {f.accepted})")

    target = episodes if total else _committed(out) + episodes  # what --total continues to
    try:
        funnel = generate(instruction, episodes, out, cfg, progress=update, plan=plan, total=total)
    except KeyboardInterrupt:
        if job is not None:
            bar.stop()
        console.print(f"interrupted: {_holds(out)}; to continue, run the same command with --total "
                      f"--episodes {target}", highlight=False)
        raise typer.Exit(130) from None
    except BackendError as exc:  # an endpoint that went away mid-run
        if job is not None:
            bar.stop()
        fail(f"{exc}; {_holds(out)}; once the endpoint answers, run the same command with --total "
             f"--episodes {target}", exit_code(exc))
    finally:
        if job is not None:
            bar.stop()
    print_funnel(funnel.to_dict(), out)
    if funnel.accepted < funnel.episodes_requested:
        fail(f"only {funnel.accepted} of the {funnel.episodes_requested} episodes asked for were "
             f"accepted ({funnel.given_up} given up after {cfg.max_attempts} attempts each); the "
             f"dataset holds {funnel.dataset_episodes}: {_advice(dict(funnel.stages))}", EXIT_PARTIAL)


def build_config(path: Path | None, mode: str, options: dict[tuple[str, ...], Any],
                 backends: dict[str, tuple[str, dict[str, Any]]]) -> GenerateConfig:
    """The run's configuration tree: a file or a preset, then every option given on the command line.

    ``options`` maps a field's path in the tree to its value (None: not given); ``backends`` maps
    ``planner``/``critic`` to (environment prefix, the endpoint's fields given: provider, base URL,
    model, timeout, retries); fields not given come from the environment.
    """
    from vcage.backends import BackendConfig
    from vcage.pipeline.config import GenerateConfig

    presets: dict[str, Callable[[], GenerateConfig]] = {"vcage": GenerateConfig,
                                                         "vanilla": GenerateConfig.vanilla}
    if mode not in presets:
        raise ConfigError(f"unknown mode {mode!r}; valid: {', '.join(presets)}")
    if path is not None:
        try:
            data = json.loads(path.read_text())
        except (OSError, ValueError) as exc:  # ValueError: not JSON, or not text at all
            raise ConfigError(f"cannot read the configuration {path}: {exc}; give a JSON file such as a "
                              "dataset's meta/vcage.json") from None
        nested = data.get("config") if isinstance(data, dict) else None
        given = nested.get("generate") if isinstance(nested, dict) else data
        if not isinstance(given, dict):
            raise ConfigError(f"the configuration {path} holds a JSON {type(given).__name__}, not an object "
                              "of options; give a dataset's meta/vcage.json or the object under its "
                              "config.generate")
        cfg = GenerateConfig.from_dict(given)
    else:
        cfg = presets[mode]()
    tree = cfg.to_dict()
    for keys, value in options.items():
        if value is not None:
            node = tree
            for key in keys[:-1]:
                if node.get(key) is None:  # e.g. a critic named on top of the Vanilla preset
                    node[key] = {}
                node = node[key]
            node[keys[-1]] = value
    for part, (prefix, fields) in backends.items():
        given = {k: v for k, v in fields.items() if v is not None}
        if given:
            if tree.get(part) is None:
                raise ConfigError(f"--{part}-* options need a {part} (Vanilla runs have no critic)")
            if tree[part].get("backend"):  # from the --config file: the options override its fields
                tree[part]["backend"].update(given)
            else:
                tree[part]["backend"] = BackendConfig.from_env(prefix, None, **given).to_dict()
    return GenerateConfig.from_dict(tree)


def cores_available() -> int:
    """The cores this process may run on (its CPU affinity, which containers and taskset narrow)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def warn_if_oversubscribed(executor: str, workers: int) -> None:
    """Warn when local workers outnumber the cores: they would share cores, each episode slower."""
    cores = cores_available()
    if executor == "local" and workers > cores:
        console.print(f"[yellow]warning:[/yellow] --workers {workers} exceeds the {cores} core(s) "
                      "available to this process: workers will share cores and each episode takes "
                      f"longer (the dataset is the same); use --workers {cores} or fewer",
                      highlight=False)


def print_funnel(stats: dict, out: Path) -> None:
    """The run's funnel: attempts by stage, rejections by reason, and a summary; fits 80 columns
    (long reasons wrap, none is cut)."""
    table = Table("stage", "attempts")
    for stage, n in sorted(stats["stages"].items(), key=lambda kv: -kv[1]):
        table.add_row(stage, str(n))
    console.print(table)
    if stats["rejections_by_reason"]:
        reasons = Table()
        reasons.add_column("rejected at: reason", overflow="fold")
        reasons.add_column("attempts", justify="right", no_wrap=True)
        for reason, n in stats["rejections_by_reason"].items():
            reasons.add_row(Text(reason), str(n))
        console.print(reasons)
    ratio = stats["total_over_physics_and_render"]
    timing = f"; total / (physics + render) = {ratio:.2f}" if ratio else ""
    console.print(
        f"accepted {stats['accepted']}/{stats['episodes_requested']} episodes in {stats['attempts']} "
        f"attempts ({stats['given_up']} given up); label noise (oracle audit of accepted): "
        f"{stats['label_noise']:.1%}; {stats['wall_seconds']:.1f} s wall, "
        f"{stats['episodes_per_hour']:.0f} episodes/hour on {stats['workers']} worker(s) "
        f"({stats['episodes_per_core_hour']:.0f} per core-hour){timing}")
    if stats["dataset_episodes"]:
        console.print(f"the dataset in {out}/ holds {stats['dataset_episodes']} episodes; this run's funnel "
                      "is appended to meta/vcage_runs.jsonl")
    else:
        console.print(f"nothing was committed, so {out}/ holds no dataset and no log of this run")


def _advice(stages: dict[str, int]) -> str:
    """What to change after a run that fell short, from where its attempts ended: more attempts help
    where they fail by chance, not where every one fails at the same stage for a reason of the scene."""
    rejected = {stage: n for stage, n in stages.items() if stage != "accepted" and n}
    if stages.get("accepted"):
        return "rerun with --total to complete it, or raise --max-attempts"
    if set(rejected) == {"placement"}:
        return ("every attempt failed to place the objects (no free space for them, see the reasons "
                "above): lower --clutter or ask for fewer objects; more attempts will not help")
    if set(rejected) == {"scene"}:
        return ("every placed scene failed the physics check (see the reasons above): lower --clutter; "
                "more attempts will not help")
    return "rerun with --total to complete it, or raise --max-attempts"


def _committed(out: Path) -> int:
    """The episodes the dataset at ``out`` holds (its commit point), 0 where there is none."""
    from vcage.data.files import committed_episodes

    return committed_episodes(out) or 0


def _holds(out: Path) -> str:
    n = _committed(out)
    if not n:
        return f"nothing was committed: {out}/ holds no dataset"
    return (f"the dataset in {out}/ holds {n} committed episodes, intact (this run's funnel is in "
            "meta/vcage_runs.jsonl)")
