"""``vcage evaluate``: a checkpoint's success rate in its dataset's evaluation environment."""

from __future__ import annotations

import json
from pathlib import Path

import typer
from rich.table import Table

from vcage.cli._app import app, console
from vcage.cli.errors import cli_errors
from vcage.errors import ConfigError


def read_scenes(path: Path) -> list[int]:
    """Scene seeds from a JSON file: a list of non-negative integers, or an object whose ``solved``
    is one (the held-out scenes ``benchmarks/policy_vcage_vs_vanilla.py`` keeps in ``eval/``)."""
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError) as exc:
        raise ConfigError(f"--scenes {path}: cannot read a JSON file ({exc})") from None
    seeds = data.get("solved") if isinstance(data, dict) else data
    if not isinstance(seeds, list) or not seeds or not all(
            isinstance(s, int) and not isinstance(s, bool) and s >= 0 for s in seeds):
        raise ConfigError(f"--scenes {path}: expected a non-empty list of scene seeds (non-negative "
                          "integers), or an object with one under 'solved'")
    return seeds


@app.command("evaluate")
@cli_errors
def evaluate_cmd(
        checkpoint: Path = typer.Argument(..., help="a checkpoint file, or a `vcage train` --out directory "
                                          "(its latest checkpoint)"),
        episodes: int = typer.Option(10, min=1, help="evaluation episodes"),
        seed: int = typer.Option(0, min=0, help="evaluation seed (scenes never seen in training)"),
        max_steps: int = typer.Option(None, min=1, help="control steps before an episode is cut "
                                      "(default: 600 per subtask)"),
        env: Path = typer.Option(None, help="evaluate in the environment of this dataset instead of the "
                                 "one the checkpoint was trained on"),
        device: str = typer.Option("cpu", help="cpu, or cuda when a GPU is present"),
        threads: int = typer.Option(None, min=1, help="torch CPU threads (default: torch's choice; 1 per "
                                    "worker with --workers)"),
        workers: int = typer.Option(1, min=1, help="processes sharing the episodes (same results as one)"),
        batch: int = typer.Option(1, min=1, help="episodes stepped together, their chunks sampled as one "
                                  "batch: faster on a CPU; results depend on it (not on --workers)"),
        training_scenes: bool = typer.Option(False, help="roll out on the scenes of the training dataset's "
                                             "first --episodes episodes instead of held-out ones: does the "
                                             "policy reproduce its own demonstrations?"),
        scenes_file: Path = typer.Option(None, "--scenes",
                                         help="roll out on the scene seeds in this JSON file (a list, or the "
                                         "experiment's eval/TASK.json: its 'solved' held-out scenes), "
                                         "episode k on the k-th; --episodes at most their number"),
        ensemble_every: int = typer.Option(0, min=0, help="temporal ensembling (ACT): predict a chunk every "
                                           "N steps and act on the weighted mean of the chunks covering "
                                           "each step (0: execute n_action_steps of each chunk)"),
        ensemble_decay: float = typer.Option(0.01, min=0.0, help="the ensemble's weight exp(-decay * i) of "
                                             "the i-th newer prediction (0: plain mean)"),
        json_out: Path = typer.Option(None, "--json",
                                      help="also write the results to this JSON file")) -> None:
    """Roll out CHECKPOINT for --episodes episodes: success rate (Wilson 95% interval), progress per
    subtask, rollouts per minute."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from vcage.data import DatasetReader
    from vcage.policy.checkpoint import load_checkpoint
    from vcage.policy.ensemble import TemporalEnsemble
    from vcage.policy.evaluate import evaluate
    from vcage.policy.evaluate import training_scenes as scenes_of

    env_config = DatasetReader(env).config if env is not None else None
    if env is not None and not env_config:
        from vcage.errors import DatasetError

        raise DatasetError(f"{env} stores no vcage configuration (meta/vcage.json); choose a vcage dataset")
    if training_scenes and scenes_file is not None:
        raise ConfigError("--training-scenes and --scenes choose the scenes two ways: give one")
    ensemble = TemporalEnsemble(ensemble_every, ensemble_decay) if ensemble_every else None
    scenes = scenes_of(load_checkpoint(checkpoint), episodes) if training_scenes else None
    if scenes_file is not None:
        scenes = read_scenes(scenes_file)
    if scenes is not None and len(scenes) < episodes:
        where = "the training dataset has" if training_scenes else f"{scenes_file} holds"
        console.print(f"[yellow]note:[/yellow] {where} {len(scenes)} scenes: evaluating on those")
        episodes = len(scenes)
    bar = Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                   TimeElapsedColumn(), console=console)
    job = bar.add_task("episodes", total=episodes)
    wins = 0

    def update(done: int, total: int, result: object) -> None:
        nonlocal wins
        if not bar.live.is_started:
            bar.start()
        wins += bool(getattr(result, "success", False))
        bar.update(job, completed=done, description=f"episodes ({wins} successes)")

    try:
        result = evaluate(checkpoint, episodes, seed=seed, max_steps=max_steps, env_config=env_config,
                          device=device, threads=threads, progress=update, workers=workers, scenes=scenes,
                          batch=batch, ensemble=ensemble)
    finally:
        if bar.live.is_started:
            bar.stop()
    low, high = result.interval
    table = Table(title=f"evaluation of {result.checkpoint}")
    table.add_column("")
    table.add_column("value", justify="right")
    table.add_row("success rate", f"{result.success_rate:.1%} ({result.successes}/{len(result.episodes)})")
    if result.unstable:
        table.add_row("physics failed (counted as failures)", str(result.unstable))
    table.add_row("Wilson 95% interval", f"[{low:.1%}, {high:.1%}]")
    table.add_row("mean progress", f"{result.mean_progress:.1%}")
    for i, share in enumerate(result.subtask_progress):
        name = result.subtask_names[i] if i < len(result.subtask_names) else ""
        table.add_row(f"subtask {i + 1} done{': ' + name if name else ''}", f"{share:.1%}")
    table.add_row("rollouts/minute", f"{result.rollouts_per_minute:.2f}")
    table.add_row("scenes", "training (the dataset's own)" if training_scenes else
                  f"{scenes_file} ({len(scenes or [])} seeds)" if scenes_file is not None else "held-out")
    if ensemble is not None:
        table.add_row("temporal ensembling",
                      f"a chunk every {ensemble.every} steps, decay {ensemble.decay:g}")
    table.add_row("seed", str(seed))
    console.print(table)
    if json_out is not None:
        json_out.write_text(json.dumps(result.to_dict(), indent=2) + "\n")
        console.print(f"wrote {json_out}")
