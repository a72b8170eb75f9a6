"""``vcage train``: a policy trained on a dataset, checkpointed into a run directory."""

from __future__ import annotations

import math
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import typer
from rich.table import Table

from vcage.cli._app import app, console
from vcage.cli.errors import cli_errors
from vcage.errors import ConfigError


@app.command("train")
@cli_errors
def train_cmd(
        dataset: Path = typer.Argument(..., help="a dataset directory (LeRobot v3)"),
        out: Path = typer.Option(..., help="run directory: checkpoints go to OUT/checkpoints/"),
        policy: str = typer.Option(None, help="diffusion (default) or mlp"),
        steps: int = typer.Option(None, help="optimiser steps in all (default 15000)"),
        epochs: float = typer.Option(None, help="the budget as passes over the data instead of --steps: "
                                     "steps = ceil(EPOCHS x frames / batch size)"),
        batch_size: int = typer.Option(None, help="samples per step (default 64)"),
        lr: float = typer.Option(None, help="peak learning rate (default 1e-3)"),
        seed: int = typer.Option(None, help="seed of the weights, batches and noise (default 0)"),
        checkpoint_every: int = typer.Option(None, help="steps between checkpoints (default 1000)"),
        obs: str = typer.Option(None, help="comma-separated observation features (default: "
                                "observation.state, observation.ee_pose and observation.environment_state "
                                "if the dataset has it); FEATURE[ELEMENT,...] observes some elements "
                                "of a feature by name, e.g. observation.state[gripper_width]"),
        action: str = typer.Option(None, help="what the policy predicts: action (default: the 7 joint "
                                   "targets and the gripper) or action.ee_pose (the tool's target pose "
                                   "and the gripper; evaluation turns it into joint targets by IK)"),
        n_obs_steps: int = typer.Option(None, min=1, help="observation frames the policy reads, the "
                                        "current one and those before it (default 2); the actions executed "
                                        "from the current frame on must fit in the 16-step chunk"),
        obs_stride: int = typer.Option(None, min=1, help="frames between two observed frames (default 1): "
                                       "with --n-obs-steps 8 --obs-stride 4 the policy sees 28 frames back "
                                       "(1.4 s at 20 Hz)"),
        rotations: str = typer.Option(None, help="how the policy reads quaternions: rot6d (default: "
                                      "rotation-matrix columns, continuous) or quaternion (as stored)"),
        keep_checkpoints: int = typer.Option(None, min=1, help="keep only this many newest checkpoints "
                                             "(default: all; each is about 20 MB at the default sizes)"),
        resume: bool = typer.Option(False, help="continue the run in OUT from its last checkpoint (only "
                                    "--steps may change)"),
        subtask_conditioned: bool = typer.Option(None, "--subtask-conditioned/--no-subtask-conditioned",
                                                 help="hierarchical: condition the policy on the plan's "
                                                 "subtask, which a classifier head names from the "
                                                 "observation during evaluation (needs subtask_index)"),
        relative_objects: bool = typer.Option(None, "--relative-objects/--no-relative-objects",
                                              help="also observe each object's position minus the tool's "
                                              "(needs observation.ee_pose and "
                                              "observation.environment_state)"),
        down_dims: str = typer.Option(None, help="the diffusion U-Net's channels per level, comma-separated "
                                      "(default 32,64,128)"),
        export: Path = typer.Option(None, help="also write the final checkpoint for evaluation only (EMA "
                                    "weights, no optimiser state: about a quarter of the size) to this file"),
        device: str = typer.Option("cpu", help="cpu, or cuda when a GPU is present"),
        cuda_graph: bool = typer.Option(False, help="on cuda: capture the training step as a CUDA graph "
                                        "and replay it (one run on an H200 at batch 256: 20 steps/s "
                                        "eager, 131 graphed; see docs/journal/benchmarks.md)"),
        threads: int = typer.Option(None, min=1, help="torch CPU threads (default: torch's choice)")) -> None:
    """Train a policy on DATASET: deterministic on the CPU given --seed, resumable with --resume."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

    from vcage.data import DatasetReader
    from vcage.policy.config import TrainConfig, split_keys
    from vcage.policy.train import stored_config, train

    given: dict[str, Any] = {"policy": policy, "steps": steps, "batch_size": batch_size, "lr": lr,
                             "seed": seed, "checkpoint_every": checkpoint_every, "rotations": rotations,
                             "action_key": action, "subtask_conditioned": subtask_conditioned,
                             "n_obs_steps": n_obs_steps, "obs_stride": obs_stride,
                             "relative_objects": relative_objects,
                             "observation_keys": split_keys(obs) if obs else None}
    given = {k: v for k, v in given.items() if v is not None}
    base = stored_config(out) if resume else None
    merged = {**(base.to_dict() if base else {}), **given}
    if down_dims:
        try:
            dims = [int(d) for d in down_dims.split(",") if d.strip()]
        except ValueError:
            raise ConfigError(f"--down-dims takes comma-separated integers, e.g. 48,96,192; got "
                              f"{down_dims!r}") from None
        merged["diffusion"] = {**merged.get("diffusion", {}), "down_dims": dims}
    config = TrainConfig.from_dict(merged)
    frames = DatasetReader(dataset, videos=False).total_frames
    if epochs is not None:
        if steps is not None:
            raise ConfigError("--steps and --epochs both set the budget: give one")
        if not epochs > 0:
            raise ConfigError(f"--epochs must be a positive number of passes over the data, got {epochs}")
        config = replace(config, steps=max(1, math.ceil(epochs * frames / config.batch_size)))
    bar = Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                   TimeElapsedColumn(), TimeRemainingColumn(), console=console)
    job = bar.add_task(f"training {config.policy}", total=config.steps)

    began = time.perf_counter()

    def update(step: int, total: int, loss: float) -> None:
        if not console.is_terminal:  # a log file gets a line at every checkpoint instead of a bar
            if step % config.checkpoint_every == 0 or step == total:
                passes = step * config.batch_size / max(frames, 1)
                console.print(f"step {step}/{total} ({passes:.1f} passes), loss {loss:.4f}, "
                              f"{time.perf_counter() - began:.0f} s", highlight=False)
            return
        if not bar.live.is_started:
            bar.start()
        bar.update(job, completed=step, description=f"training {config.policy} (loss {loss:.4f})")

    try:
        summary = train(dataset, out, config, resume=resume, device=device, threads=threads, progress=update,
                        keep=keep_checkpoints, graph=cuda_graph)
    finally:
        if bar.live.is_started:
            bar.stop()
    for note in summary.notes:
        console.print(f"[yellow]note:[/yellow] {note}")
    table = Table(title=f"{config.policy} policy on {dataset}")
    table.add_column("")
    table.add_column("value", justify="right")
    table.add_row("steps", f"{summary.start_step} -> {summary.steps}" if summary.start_step
                  else str(summary.steps))
    table.add_row("passes over the data", f"{summary.steps * config.batch_size / max(frames, 1):.1f} "
                  f"({frames:,} frames, batch {config.batch_size})")
    table.add_row("final loss (mean of last 50 steps)", f"{summary.final_loss:.5f}")
    table.add_row("samples/s", f"{summary.samples_per_second:,.0f}")
    table.add_row("training time", f"{summary.seconds:.1f} s")
    table.add_row("parameters", f"{summary.parameters:,}")
    table.add_row("checkpoint", str(summary.checkpoint))
    if export is not None:
        from vcage.policy.checkpoint import export_for_evaluation

        table.add_row("exported for evaluation", str(export_for_evaluation(summary.checkpoint, export)))
    console.print(table)
