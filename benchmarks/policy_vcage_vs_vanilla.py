"""Downstream value of verified data, in the shape of the paper's Table 1: the same policy trained on
V-CAGE data and on Vanilla data of the same tasks and seeds, evaluated on the same held-out scenes.

For each task of the suite (single-subtask instructions and long-horizon goals):

1. generate ``--demos`` episodes with V-CAGE (context-aware placement, scene check, image critic)
   and with Vanilla (naive placement, no check, no critic) on the same run seed;
2. pick ``--eval`` held-out scenes that the scripted expert solves: evaluation scene seeds of the
   V-CAGE dataset's environment (:mod:`vcage.pipeline.evaluation`, disjoint from every generation
   seed) on which the plan's scripted execution succeeds by the oracle;
3. train ``--policy`` on each dataset with each of ``--train-seeds`` seeds and the same budget (by
   default a diffusion policy that reads the tool's and the plan objects' poses and predicts the
   tool's next poses, the configuration that did best on "put the mouse on the pad");
4. evaluate every checkpoint on the same held-out scenes, in the V-CAGE environment (both datasets
   share the plan, so the policies observe and act alike; Vanilla's own environment would sample
   its unchecked scenes), and on ``--fit`` scenes of its own training episodes (column "fit"): a
   policy that fails there cannot reproduce its demonstrations, whatever their labels.

Then it prints, per task and method, the success rate (pooled over training seeds, Wilson 95%
interval) and Vanilla's label noise; overall, Avg SR and Top-K SR computed two ways (the paper does
not say which it means: "tasks" = the mean of the K tasks with the best success rate, "checkpoints"
= the mean over tasks of each task's K best checkpoints, which needs at least K training seeds),
the paired bootstrap 95% interval of the V-CAGE - Vanilla gap (resampling tasks, then scenes), and
the correlation of each task's gap with its Vanilla label noise.

By default the processes are as many as the usable cores and rollouts go in batches of 8.

Every step is resumable: datasets are completed (``generate(..., total=True)``), training resumes
from its last checkpoint, finished evaluations are read back from ``WORK/results``. ``--quick`` is
the smoke path (one task, two demos, a few training steps, one short evaluation episode): it shows
the loop runs, and its figures mean nothing.

    LP_NUM_THREADS=1 .venv/bin/python benchmarks/policy_vcage_vs_vanilla.py --work /tmp/policy-exp

The three stages can also run apart (``--stage``), training on another machine: ``data`` makes the
datasets and held-out scenes; ``train`` needs only torch and the datasets (not the simulator), so
it runs where a GPU is (``--device cuda``; ``--budget SECONDS`` first times a short probe of all
runs at once and picks the largest multiple of 1,000 steps that fits, the same for every run;
``--export DIR`` writes each final checkpoint for evaluation only, with the run's timings);
``evaluate --import DIR`` puts such checkpoints in place and rolls them out.

A full run takes longer than a working session may last, and a work folder may not survive between
sessions. ``--ledger DIR`` keeps what a finished task measured (its results, label noise, failure
kinds, held-out scenes and loss curves) in one small JSON file per task, stamped with a fingerprint
of the code (the package's files, this script, the libraries' versions) and the settings: a later
run with the same ledger skips the tasks it holds (and refuses to add tasks from other code or
settings), and ``--stage report --ledger DIR`` prints the table and draws the curves from the
ledger alone, so one table can be assembled over several sessions from one commit.
"""

from __future__ import annotations

import argparse
import functools
import hashlib
import json
import os
import re
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

SUITE = (
    "press the bell",
    "put the mouse on the pad",
    "stack the blocks",
    "get ready for work",
    "put the mouse on the pad, then press the bell",
)
QUICK_SUITE = ("press the bell",)
# what the policies observe unless told: the tool's pose and the poses of the plan's objects, without the
# joint state (with it, tool-pose policies drifted where the IK left the elbow; docs/journal/benchmarks.md,
# "joint targets or tool poses")
DEFAULT_OBS = ("observation.ee_pose", "observation.environment_state")
METHODS = ("vcage", "vanilla")


def slug(text: str) -> str:
    return re.sub(r"[^a-z0-9]+", "_", text.lower()).strip("_")[:60]


def generation_config(method: str, seed: int, size: int, workers: int = 1) -> Any:
    from vcage.config import RenderConfig
    from vcage.pipeline.config import ExecutorConfig, GenerateConfig

    render = RenderConfig(size=(size, size), cameras=("front",))  # state-based policies: one small video
    cfg = GenerateConfig(seed=seed) if method == "vcage" else GenerateConfig.vanilla(seed=seed)
    return replace(cfg, render=render, executor=ExecutorConfig(workers=workers))


def make_datasets(task: str, work: Path, demos: int, seed: int, size: int,
                  workers: int = 1) -> dict[str, Path]:
    from vcage.pipeline.generate import generate

    out = {}
    for method in METHODS:
        root = dataset_dir(work, task, method)
        funnel = generate(task, demos, root, generation_config(method, seed, size, workers), total=True)
        print(f"  {method:8s} {funnel.dataset_episodes} demos ({funnel.attempts} attempts this run)",
              flush=True)
        out[method] = root
    return out


def solvable_scenes(task: str, dataset: Path, work: Path, count: int, base: int) -> list[int]:
    """``count`` evaluation scene seeds on which the scripted expert succeeds (cached in WORK)."""
    from vcage.data import DatasetReader
    from vcage.pipeline.config import GenerateConfig
    from vcage.pipeline.episode import attempt
    from vcage.pipeline.evaluation import eval_seed
    from vcage.planning.schema import Plan

    path = work / "eval" / f"{slug(task)}.json"
    state = json.loads(path.read_text()) if path.is_file() else {"tried": 0, "solved": [], "failed": []}
    config = DatasetReader(dataset).config or {}
    plan, cfg = Plan.model_validate(config["plan"]), GenerateConfig.from_dict(config["generate"])
    while len(state["solved"]) < count:
        if state["tried"] >= 20 * count:
            raise SystemExit(f"{task}: the expert solved only {len(state['solved'])} of {state['tried']} "
                             "evaluation scenes")
        scene_seed = eval_seed(base, state["tried"], 0)
        result = attempt(plan, scene_seed, cfg, None)
        (state["solved"] if result.oracle_success else state["failed"]).append(scene_seed)
        state["tried"] += 1
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(state))
    return list(state["solved"][:count])


def result_path(work: Path, task: str, method: str, train_seed: int) -> Path:
    return work / "results" / slug(task) / method / f"seed{train_seed}.json"


def dataset_dir(work: Path, task: str, method: str) -> Path:
    return work / "data" / slug(task) / method


def run_dir(work: Path, task: str, method: str, train_seed: int) -> Path:
    return work / "runs" / slug(task) / method / f"seed{train_seed}"


TRAINED = "train.json"  # in a run directory: the finished run's timings, written by the train stage
PROBE_STEPS = 300


def train_config(args: argparse.Namespace, train_seed: int) -> Any:
    from vcage.policy import DiffusionConfig, TrainConfig

    steps = args.steps
    diffusion = DiffusionConfig() if args.down_dims is None else \
        DiffusionConfig(down_dims=tuple(args.down_dims))
    return TrainConfig(policy=args.policy, steps=steps, lr=args.lr, seed=train_seed,
                       batch_size=args.batch_size, diffusion=diffusion, action_key=args.action,
                       observation_keys=tuple(args.obs) if args.obs else None,
                       subtask_conditioned=args.subtask_conditioned, n_obs_steps=args.n_obs_steps,
                       obs_stride=args.obs_stride,
                       checkpoint_every=max(1, min(args.checkpoint_every, steps)))


def train_run(dataset: Path, run: Path, config: Any, threads: int,
              device: str = "cpu", graph: bool = False) -> tuple[float, float, float]:
    """One training run (resumed if interrupted): its seconds, samples per second and final loss,
    also written to ``run/train.json`` once the run has reached its steps."""
    from vcage.policy.train import train

    summary = train(dataset, run, config, resume=True, device=device, threads=threads, keep=2, graph=graph)
    done = (summary.seconds, summary.samples_per_second, summary.final_loss)
    if summary.start_step < summary.steps:  # a run resumed at its end measured nothing: keep the first record
        (run / TRAINED).write_text(json.dumps({
            "seconds": summary.seconds, "samples_per_second": summary.samples_per_second,
            "final_loss": summary.final_loss, "steps": summary.steps, "resumed_from": summary.start_step,
            "parameters": summary.parameters, "device": device, "cuda_graph": graph,
            "batch_size": config.batch_size}, indent=1))
    return done


def trained_record(run: Path) -> tuple[float, float, float] | None:
    """The timings the train stage recorded for a finished run, if it did."""
    path = run / TRAINED
    if not path.is_file():
        return None
    r = json.loads(path.read_text())
    return float(r["seconds"]), float(r["samples_per_second"]), float(r["final_loss"])


def train_all(jobs: list[tuple[Path, Path, Any]], workers: int, threads: int,
              device: str = "cpu", graph: bool = False) -> dict[Path, tuple[float, float, float]]:
    """The training runs of ``jobs`` (dataset, run directory, config), ``workers`` at a time in
    spawned processes (training is single-threaded at these sizes: processes use the cores; on a
    GPU the runs share it, each launching its own small kernels)."""
    if workers <= 1 or len(jobs) <= 1:
        return {run: train_run(dataset, run, config, threads, device, graph) for dataset, run, config in jobs}
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    spawn = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(min(workers, len(jobs)), mp_context=spawn) as pool:
        futures = {run: pool.submit(train_run, dataset, run, config, threads, device, graph)
                   for dataset, run, config in jobs}
        return {run: future.result() for run, future in futures.items()}


def budget_steps(jobs: list[tuple[Path, Path, Any]], budget: float, work: Path, workers: int, threads: int,
                 device: str, probe_steps: int = PROBE_STEPS, graph: bool = False) -> int:
    """The training steps per run that fit ``budget`` seconds when ``jobs`` are trained ``workers``
    at a time: that many of them train ``probe_steps`` steps (warm-up included, so the estimate errs
    short) into a scratch directory at the same time; the slowest sets the rate, and the runs take
    ceil(jobs / workers) turns. A multiple of 1,000, at least 1,000."""
    import shutil

    at_once = max(1, min(workers, len(jobs)))
    turns = -(-len(jobs) // at_once)
    scratch = work / "probe"
    shutil.rmtree(scratch, ignore_errors=True)
    probes = [(dataset, scratch / f"{i}", replace(config, steps=probe_steps, checkpoint_every=probe_steps))
              for i, (dataset, _, config) in enumerate(jobs[:at_once])]
    timings = train_all(probes, at_once, threads, device, graph)
    shutil.rmtree(scratch, ignore_errors=True)
    rate = min(probe_steps / seconds for seconds, _, _ in timings.values())
    steps = max(1000, int(rate * budget / turns) // 1000 * 1000)
    print(f"  probe: {at_once} runs at once, the slowest at {rate:.1f} steps/s; {len(jobs)} runs in {turns} "
          f"turns: {steps} steps each for a {budget:.0f} s budget", flush=True)
    return steps


def train_and_evaluate(task: str, method: str, dataset: Path, env_config: dict[str, Any], scenes: list[int],
                       train_seed: int, args: argparse.Namespace, work: Path,
                       trained: tuple[float, float, float] | None = None) -> dict[str, Any]:
    from vcage.pipeline.evaluation import make_env
    from vcage.policy.evaluate import evaluate

    path = result_path(work, task, method, train_seed)
    if path.is_file():
        return dict(json.loads(path.read_text()))
    run = run_dir(work, task, method, train_seed)
    trained = trained or trained_record(run)
    if trained is None and args.stage == "evaluate":
        raise SystemExit(f"{run} holds no finished training run: run --stage train first (or --import the "
                         "checkpoints trained elsewhere)")
    seconds, rate, loss = trained or train_run(dataset, run, train_config(args, train_seed), args.threads,
                                               args.device, args.cuda_graph)
    evaluation = evaluate(run, len(scenes), seed=0, max_steps=args.max_steps, env_config=env_config,
                          threads=args.threads, make_env=functools.partial(make_env, scenes=scenes),
                          workers=args.workers, batch=args.eval_batch)
    fit = None
    if args.fit:  # the same checkpoint on scenes of its own training episodes: does it fit its data?
        from vcage.data import DatasetReader
        from vcage.policy.checkpoint import load_checkpoint
        from vcage.policy.evaluate import training_scenes

        own = training_scenes(load_checkpoint(run), args.fit)
        # in the environment of its own dataset: a Vanilla episode's seed builds its scene only with
        # Vanilla's sampler (V-CAGE's would place the same objects elsewhere)
        fit = evaluate(run, len(own), seed=0, max_steps=args.max_steps,
                       env_config=DatasetReader(dataset).config, threads=args.threads, scenes=own,
                       workers=args.workers, batch=args.eval_batch)
    out = evaluation.to_dict() | {"task": task, "method": method, "train_seed": train_seed,
                                  "fit": None if fit is None else {"episodes": len(fit.episodes),
                                                                   "successes": fit.successes,
                                                                   "environment": str(dataset)},
                                  "eval_batch": args.eval_batch,
                                  "train_seconds": seconds, "train_samples_per_second": rate,
                                  "final_loss": loss}
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(out, indent=1))
    return out


def cached_evaluation(path: Path, make: Callable[[], Any]) -> dict[str, Any]:
    """The evaluation stored at ``path`` (JSON), made by ``make()`` (an ``Evaluation``) and stored
    first if it is not there: an interrupted experiment resumes without rolling out again."""
    if not path.is_file():
        path.write_text(json.dumps(make().to_dict()))
    return dict(json.loads(path.read_text()))


def wilson(successes: int, n: int) -> tuple[float, float]:
    from vcage.policy.metrics import wilson_interval

    return wilson_interval(successes, n)


def top_k(rates: dict[str, list[float]], k: int, how: str) -> float | None:
    """Top-K SR: ``tasks``: mean of the K tasks with the best (seed-averaged) rate; ``checkpoints``:
    mean over tasks of each task's K best checkpoints (None when a task has fewer than K)."""
    if how == "tasks":
        means = sorted((float(np.mean(v)) for v in rates.values()), reverse=True)
        return float(np.mean(means[:k])) if len(means) >= k else None
    if any(len(v) < k for v in rates.values()):
        return None
    return float(np.mean([np.mean(sorted(v, reverse=True)[:k]) for v in rates.values()]))


def bootstrap_gap(outcomes: dict[str, dict[str, np.ndarray]], draws: int, rng: np.random.Generator
                  ) -> tuple[float, float, float]:
    """Mean V-CAGE - Vanilla success gap and its paired bootstrap 95% interval: tasks resampled,
    then the held-out scenes of each drawn task (outcomes: task -> method -> (seeds, scenes))."""
    tasks = sorted(outcomes)
    gap = float(np.mean([outcomes[t]["vcage"].mean() - outcomes[t]["vanilla"].mean() for t in tasks]))
    samples = []
    for _ in range(draws):
        drawn = rng.choice(len(tasks), size=len(tasks))
        diffs = []
        for i in drawn:
            v, b = outcomes[tasks[i]]["vcage"], outcomes[tasks[i]]["vanilla"]
            scenes = rng.choice(v.shape[1], size=v.shape[1])
            diffs.append(v[:, scenes].mean() - b[:, scenes].mean())
        samples.append(np.mean(diffs))
    low, high = np.percentile(samples, [2.5, 97.5])
    return gap, float(low), float(high)


def report(results: list[dict[str, Any]], noise: dict[str, float], draws: int) -> dict[str, Any]:
    """Print the table (per task and method, the averages, the paired gap); return its figures."""
    summary: dict[str, Any] = {"tasks": {}, "avg": {}, "gap": None}
    by: dict[str, dict[str, list[dict[str, Any]]]] = {}
    for r in results:
        by.setdefault(r["task"], {}).setdefault(r["method"], []).append(r)
    print(f"\n{'task':48s} {'method':8s} {'SR':>6s} {'Wilson 95%':>15s} {'n':>5s} {'progress':>9s} "
          f"{'fit':>9s} {'vanilla noise':>14s}")
    rates: dict[str, dict[str, list[float]]] = {m: {} for m in METHODS}
    outcomes: dict[str, dict[str, np.ndarray]] = {}
    for task, methods in by.items():
        for method in METHODS:
            runs = methods.get(method, [])
            if not runs:
                continue
            s, n = sum(r["successes"] for r in runs), sum(r["episodes"] for r in runs)
            low, high = wilson(s, n)
            progress = np.mean([r["mean_progress"] for r in runs])
            rates[method][task] = [r["success_rate"] for r in runs]
            ordered = sorted(runs, key=lambda r: r["train_seed"])
            outcomes.setdefault(task, {})[method] = np.array(
                [[e["success"] for e in r["per_episode"]] for r in ordered], dtype=float)
            fits = [r["fit"] for r in runs if r.get("fit")]
            fit = f"{sum(f['successes'] for f in fits)}/{sum(f['episodes'] for f in fits)}" if fits \
                else "n/a"
            summary["tasks"].setdefault(task, {})[method] = (s, n)
            print(f"{task[:48]:48s} {method:8s} {s / n:6.1%} {f'[{low:.0%}, {high:.0%}]':>15s} {n:5d} "
                  f"{progress:9.2f} {fit:>9s} {noise.get(task, float('nan')):14.1%}")
    print(f"\n{'':14s} {'Avg SR':>8s} {'Top-5 (tasks)':>14s} {'Top-10 (tasks)':>15s} "
          f"{'Top-5 (ckpts)':>14s} {'Top-10 (ckpts)':>15s}")
    for method in METHODS:
        r = rates[method]
        if not r:
            continue
        avg = float(np.mean([np.mean(v) for v in r.values()]))
        summary["avg"][method] = avg
        cells = [top_k(r, k, how) for how in ("tasks", "checkpoints") for k in (5, 10)]
        shown = ["n/a" if c is None else f"{c:.1%}" for c in cells]
        print(f"{method:14s} {avg:8.1%} {shown[0]:>14s} {shown[1]:>15s} {shown[2]:>14s} {shown[3]:>15s}")
    paired = {t: m for t, m in outcomes.items() if set(m) == set(METHODS)
              and m["vcage"].shape == m["vanilla"].shape}
    if paired:
        gap, low, high = bootstrap_gap(paired, draws, np.random.default_rng(0))
        summary["gap"] = (gap, low, high, len(paired))
        print(f"\nV-CAGE - Vanilla success gap: {gap:+.1%} (paired bootstrap 95%: [{low:+.1%}, {high:+.1%}], "
              f"{len(paired)} tasks)")
        gaps = [paired[t]["vcage"].mean() - paired[t]["vanilla"].mean() for t in paired]
        noises = [noise.get(t, float("nan")) for t in paired]
        if len(paired) >= 3 and np.std(gaps) > 0 and np.std(noises) > 0:
            corr = np.corrcoef(gaps, noises)[0, 1]
            print(f"correlation of the per-task gap with Vanilla's label noise: {corr:+.2f}")
        subtask_gaps(by, paired, draws)
    return summary


def subtask_gaps(by: dict[str, dict[str, list[dict[str, Any]]]], paired: dict[str, Any], draws: int) -> None:
    """For each goal of several subtasks: how many held-out episodes got past each subtask, per
    method, and the paired bootstrap interval of the gap (a goal no policy completes can still
    show which data teaches its first steps)."""
    rng = np.random.default_rng(1)
    for task in paired:
        names = by[task]["vcage"][0].get("subtask_names") or []
        if len(names) < 2:
            continue
        print(f"\n{task}: episodes past each subtask (V-CAGE, Vanilla; gap with its paired bootstrap 95%)")
        for k, name in enumerate(names):
            done = {m: np.array([[e["subtasks_done"] > k for e in r["per_episode"]]
                                 for r in sorted(by[task][m], key=lambda r: r["train_seed"])], dtype=float)
                    for m in METHODS}
            gap, low, high = bootstrap_gap({task: done}, draws, rng)
            print(f"  {k + 1}. {name[:56]:56s} {int(done['vcage'].sum()):4d}/{done['vcage'].size:<4d} "
                  f"{int(done['vanilla'].sum()):4d}/{done['vanilla'].size:<4d} {gap:+.1%} "
                  f"[{low:+.1%}, {high:+.1%}]")


def export_name(task: str, method: str, train_seed: int) -> str:
    return f"{slug(task)}.{method}.seed{train_seed}.pt"


def export_runs(runs: list[tuple[str, str, int]], work: Path, folder: Path) -> None:
    """Each finished run's last checkpoint, for evaluation only, with its train-stage timings."""
    from vcage.policy.checkpoint import export_for_evaluation, latest_checkpoint

    for task, method, seed in runs:
        run = run_dir(work, task, method, seed)
        latest = latest_checkpoint(run)
        if latest is None or not (run / TRAINED).is_file():
            raise SystemExit(f"{run} has not finished training: nothing to export")
        out = export_for_evaluation(latest, folder / export_name(task, method, seed),
                                    trained=json.loads((run / TRAINED).read_text()))
        print(f"  exported {out} ({out.stat().st_size / 2**20:.1f} MiB)", flush=True)


def import_runs(runs: list[tuple[str, str, int]], work: Path, folder: Path) -> None:
    """Put exported checkpoints where the evaluate stage finds them (a run already evaluated is left)."""
    import shutil

    from vcage.policy.checkpoint import checkpoint_path, load_checkpoint

    for task, method, seed in runs:
        source = folder / export_name(task, method, seed)
        if not source.is_file() or result_path(work, task, method, seed).is_file():
            continue
        payload = load_checkpoint(source)
        run = run_dir(work, task, method, seed)
        target = checkpoint_path(run, int(payload["step"]))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(source, target)
        (run / TRAINED).write_text(json.dumps(payload["trained"], indent=1))
        print(f"  imported {source} as {target}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--work", type=Path, required=True, help="directory of datasets, runs and results")
    parser.add_argument("--tasks", nargs="+", default=None, help="instructions (default: the suite)")
    parser.add_argument("--demos", type=int, default=50)
    parser.add_argument("--eval", type=int, default=50, help="held-out scenes per task")
    parser.add_argument("--train-seeds", type=int, default=3)
    parser.add_argument("--policy", choices=("diffusion", "mlp"), default="diffusion")
    parser.add_argument("--action", choices=("action", "action.ee_pose"), default="action.ee_pose",
                        help="what the policies predict: the tool's pose (IK in the env; the default) or "
                        "joint targets")
    parser.add_argument("--obs", nargs="+", default=list(DEFAULT_OBS),
                        help="observation features (default: the tool's pose and the plan objects' poses; "
                        "'all' for the dataset's state, tool pose and environment state)")
    parser.add_argument("--subtask-conditioned", action="store_true",
                        help="condition the policies on the plan's subtask, named by a classifier head at "
                        "evaluation (hierarchical; goals only need it)")
    parser.add_argument("--n-obs-steps", type=int, default=2, help="observation frames the policies read")
    parser.add_argument("--obs-stride", type=int, default=1, help="frames between two observed frames")
    parser.add_argument("--steps", type=int, default=15000, help="training steps per checkpoint run")
    parser.add_argument("--lr", type=float, default=1e-3, help="peak learning rate")
    parser.add_argument("--batch-size", type=int, default=64)
    parser.add_argument("--down-dims", type=int, nargs="+", default=None,
                        help="the diffusion U-Net's channels per level (default 32 64 128)")
    parser.add_argument("--checkpoint-every", type=int, default=500,
                        help="training steps between checkpoints")
    parser.add_argument("--max-steps", type=int, default=None, help="evaluation episode length cap")
    parser.add_argument("--seed", type=int, default=0, help="generation run seed (both methods)")
    parser.add_argument("--size", type=int, default=64, help="video size (the policy is state-based)")
    parser.add_argument("--threads", type=int, default=1, help="torch threads per process")
    parser.add_argument("--workers", type=int, default=None,
                        help="processes for generation, training runs and rollouts (same results as one; "
                        "default: the usable cores, 1 with --quick)")
    parser.add_argument("--eval-batch", type=int, default=8,
                        help="evaluation episodes stepped together, chunks sampled as one batch (faster; "
                             "results depend on it)")
    parser.add_argument("--fit", type=int, default=10,
                        help="also roll out each checkpoint on this many of its own training scenes (0: no)")
    parser.add_argument("--bootstrap", type=int, default=2000)
    parser.add_argument("--stage", choices=("all", "data", "train", "evaluate", "report"), default="all",
                        help="run one stage only (see the module's help); default: all three; 'report': "
                        "the table from --ledger alone")
    parser.add_argument("--ledger", type=Path, default=None,
                        help="one JSON file per finished task: skip the tasks it holds, add those finished")
    parser.add_argument("--record", action="store_true", help="with --stage report: write the whole table's "
                        "figures to docs/results/policy_table1.json (the results page)")
    parser.add_argument("--ledger-commit", default=None, help="with --record: the commit whose code made the "
                        "ledger (its entries hold only a fingerprint of the code)")
    parser.add_argument("--ledger-patch", default=None, help="with --record: what was applied to that "
                        "commit, if anything (recorded as COMMIT+patched with this note)")
    parser.add_argument("--device", default="cpu", help="training device: cpu, or cuda on a GPU machine")
    parser.add_argument("--cuda-graph", action="store_true",
                        help="with --device cuda: capture each run's training step as a CUDA graph")
    parser.add_argument("--budget", type=float, default=None,
                        help="train stage: pick --steps to fit this many seconds (a probe times all runs)")
    parser.add_argument("--probe-steps", type=int, default=PROBE_STEPS,
                        help="train stage: steps of the --budget probe (many runs at once make each slow)")
    parser.add_argument("--export", type=Path, default=None,
                        help="train stage: also write each final checkpoint, for evaluation only, here")
    parser.add_argument("--import", dest="import_from", type=Path, default=None,
                        help="evaluate stage: first put the checkpoints --export wrote here in place")
    parser.add_argument("--quick", action="store_true", help="smoke path: tiny everything")
    args = parser.parse_args()
    if args.quick:
        args.tasks = args.tasks or list(QUICK_SUITE)
        args.demos, args.eval, args.train_seeds, args.steps = 2, 1, 1, 4
        args.policy, args.max_steps, args.bootstrap, args.fit = "mlp", 20, 50, 1
        args.workers = 1 if args.workers is None else args.workers
    if args.workers is None:
        args.workers = len(os.sched_getaffinity(0))
    if args.obs == ["all"]:
        args.obs = None
    tasks = args.tasks or list(SUITE)
    t0 = time.perf_counter()
    if args.stage == "report":
        if args.ledger is None:
            raise SystemExit("--stage report reads the table from --ledger DIR: name the folder")
        made = None
        if args.record:
            made = ledger_made(args.ledger_commit, args.ledger_patch)
        report_ledger(args.ledger, tasks, args.bootstrap, made)
        return
    if args.stage == "train":
        train_stage(tasks, args)
        print(f"\n{len(tasks)} tasks, {args.train_seeds} training seeds, policy {args.policy} ({args.steps} "
              f"steps) on {args.device}; {time.perf_counter() - t0:.0f} s")
        return
    results: list[dict[str, Any]] = []
    noise: dict[str, float] = {}
    curves_of: dict[tuple[str, str, int], tuple[list[int], list[float]]] = {}
    stamp = ledger_stamp(args) if args.ledger is not None else None
    for task in tasks:
        print(f"{task}:", flush=True)
        reuse = args.ledger is not None and args.stage == "all"
        entry = read_entry(args.ledger, task, stamp) if reuse else None
        if entry is not None:
            print(f"  from the ledger ({args.ledger / ledger_name(task)})", flush=True)
            results += entry["results"]
            noise[task] = entry["noise"]
            curves_of |= entry_curves(entry)
            continue
        datasets, scenes, noise[task] = data_stage(task, args)
        if args.stage == "data":
            continue
        done = evaluate_stage(task, args, datasets, scenes)
        results += done
        curves_of |= {(task, m, s): c for m in METHODS for s in range(args.train_seeds)
                      if (c := loss_curve(run_dir(args.work, task, m, s))) is not None}
        if args.ledger is not None and stamp is not None:
            write_entry(args.ledger, task, stamp, noise[task], failure_kinds(datasets["vanilla"]), scenes,
                        done, curves_of)
    if args.stage == "data":
        return
    report(results, noise, args.bootstrap)
    curves = plot_curves(curves_of, tasks, args.work / "learning_curves.png")
    if curves is not None:
        print(f"\nlearning curves: {curves}")
    found = (re.search(r"step-(\d+)", str(r["checkpoint"])) for r in results)
    steps = sorted({int(m.group(1)) for m in found if m})
    print(f"\n{len(tasks)} tasks, {args.demos} demos per method, {args.train_seeds} training seeds, "
          f"{args.eval} held-out scenes, policy {args.policy} "
          f"({', '.join(map(str, steps)) or args.steps} steps); {time.perf_counter() - t0:.0f} s")


def data_stage(task: str, args: argparse.Namespace) -> tuple[dict[str, Path], list[int], float]:
    """The task's two datasets (completed to ``--demos``), the held-out scenes, and Vanilla's label noise."""
    from vcage.pipeline.audit import audit

    datasets = make_datasets(task, args.work, args.demos, args.seed, args.size, args.workers)
    noise = audit(datasets["vanilla"]).label_noise
    scenes = solvable_scenes(task, datasets["vcage"], args.work, args.eval, base=1000 + args.seed)
    print(f"  {len(scenes)} held-out scenes; Vanilla label noise {noise:.1%}", flush=True)
    kinds = failure_kinds(datasets["vanilla"])
    if kinds:
        print("  what the oracle finds wrong in Vanilla's demos (a demo may fail several): "
              + ", ".join(f"{what} in {n}" for what, n in kinds.items()), flush=True)
    return datasets, scenes, noise


def failure_kinds(dataset: Path) -> dict[str, int]:
    """How many of the dataset's kept episodes fail each oracle predicate (or end in a skill error),
    most frequent first: what the label noise consists of."""
    from collections import Counter

    from vcage.data.layout import ATTEMPTS_LOG
    from vcage.pipeline.attempt_log import read
    from vcage.pipeline.stage import Stage

    counts: Counter[str] = Counter()
    for rec in read(dataset / ATTEMPTS_LOG, torn_tail=False):
        if rec["stage"] != Stage.ACCEPTED or rec["oracle_success"]:
            continue
        wrong = {what for row in rec["audit"] for what, holds in row["oracle"].items() if not holds}
        wrong |= {f"skill error in {row['skill']}" for row in rec["audit"] if row.get("skill_error")}
        counts.update(wrong)
    return dict(counts.most_common())


def loss_curve(run: Path, points: int = 200) -> tuple[list[int], list[float]] | None:
    """The run's training loss as a moving mean over 1% of its steps, at about ``points`` steps
    (None when the run has no checkpoint)."""
    from vcage.policy.checkpoint import latest_checkpoint, load_checkpoint

    latest = latest_checkpoint(run)
    if latest is None:
        return None
    loss = np.asarray(load_checkpoint(latest)["loss_history"], dtype=float)
    width = max(1, len(loss) // 100)
    smooth = np.convolve(loss, np.ones(width) / width, mode="valid")
    at = np.unique(np.linspace(0, len(smooth) - 1, min(points, len(smooth))).round().astype(int))
    return [int(i) + width for i in at], [float(smooth[i]) for i in at]


def plot_curves(curves: dict[tuple[str, str, int], tuple[list[int], list[float]]], tasks: list[str],
                path: Path) -> Path | None:
    """Each run's loss curve (:func:`loss_curve`), per task, V-CAGE against Vanilla, into ``path``
    (PNG); None when there is no curve."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if not curves:
        return None
    fig, axes = plt.subplots(1, len(tasks), figsize=(3.2 * len(tasks), 2.8), squeeze=False)
    for ax, task in zip(axes[0], tasks, strict=True):
        for method, colour in zip(METHODS, ("tab:blue", "tab:orange"), strict=True):
            for (t, m, seed), (steps, loss) in sorted(curves.items()):
                if (t, m) == (task, method):
                    ax.plot(steps, loss, color=colour, lw=1, ls=("-", "--", ":")[seed % 3],
                            label=f"{method} seed {seed}")
        ax.set_yscale("log")
        ax.set_title(task if len(task) <= 28 else task[:26] + "...", fontsize=8)
        ax.set_xlabel("training step", fontsize=8)
        ax.tick_params(labelsize=7)
    axes[0][0].set_ylabel("denoising loss", fontsize=8)
    axes[0][0].legend(fontsize=6)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


LEDGER_FORMAT = 1
# the settings a table's rows must share (the rest, such as --workers or --threads, change no result)
SETTINGS = ("demos", "eval", "train_seeds", "policy", "action", "obs", "subtask_conditioned", "n_obs_steps",
            "obs_stride", "steps", "lr", "batch_size", "down_dims", "checkpoint_every", "max_steps", "seed",
            "size", "eval_batch", "fit")


def code_fingerprint() -> str:
    """A digest of what the results depend on: the vcage package's files, this script, and the versions
    of the libraries (simulator, solvers, torch)."""
    from importlib.metadata import version

    from vcage.provenance import source_digest, versions

    digest = hashlib.sha256(source_digest().encode())
    digest.update(Path(__file__).read_bytes())
    digest.update(json.dumps(versions() | {"torch": version("torch")}, sort_keys=True).encode())
    return digest.hexdigest()[:16]


def ledger_stamp(args: argparse.Namespace) -> dict[str, Any]:
    """What a ledger entry must share with a run that reuses it."""
    return {"format": LEDGER_FORMAT, "code": code_fingerprint(),
            "settings": {k: getattr(args, k) for k in SETTINGS}}


def ledger_name(task: str) -> str:
    return f"{slug(task)}.json"


def read_entry(ledger: Path, task: str, stamp: dict[str, Any] | None) -> dict[str, Any] | None:
    """The ledger's entry for ``task`` (None when it has none); with ``stamp``, refused unless it was
    made by the same code with the same settings."""
    path = ledger / ledger_name(task)
    if not path.is_file():
        return None
    try:
        entry = dict(json.loads(path.read_text()))
    except json.JSONDecodeError as e:
        raise SystemExit(f"{path} is not a ledger entry ({e}): remove it to run the task again") from e
    if entry.get("task") != task or entry.get("format") != LEDGER_FORMAT:
        raise SystemExit(f"{path} is not this ledger's entry for {task!r}: remove it to run the task again")
    if stamp is not None:
        differs = [k for k in ("code", "settings") if entry[k] != stamp[k]]
        if differs:
            raise SystemExit(f"{path} was made with other {' and '.join(differs)} than this run "
                             f"({entry['code']} vs {stamp['code']}): one table comes from one code and one "
                             "set of settings; use another ledger, or run from the code that made it")
    return entry


def write_entry(ledger: Path, task: str, stamp: dict[str, Any], noise: float, kinds: dict[str, int],
                scenes: list[int], results: list[dict[str, Any]],
                curves: dict[tuple[str, str, int], tuple[list[int], list[float]]]) -> Path:
    """The finished task's entry, written whole (a temporary file renamed over the target)."""
    from datetime import UTC, datetime

    entry = stamp | {"task": task, "written": datetime.now(UTC).isoformat(timespec="seconds"),
                     "noise": noise, "failure_kinds": kinds, "scenes": scenes, "results": results,
                     "curves": [{"method": m, "train_seed": s, "steps": c[0], "loss": c[1]}
                                for (t, m, s), c in sorted(curves.items()) if t == task]}
    ledger.mkdir(parents=True, exist_ok=True)
    path = ledger / ledger_name(task)
    partial = path.with_suffix(".json.partial")
    partial.write_text(json.dumps(entry, indent=1))
    partial.replace(path)
    print(f"  ledger: {path}", flush=True)
    return path


def entry_curves(entry: dict[str, Any]) -> dict[tuple[str, str, int], tuple[list[int], list[float]]]:
    return {(entry["task"], c["method"], int(c["train_seed"])): (c["steps"], c["loss"])
            for c in entry["curves"]}


def ledger_made(commit: str | None, patch: str | None) -> dict[str, str]:
    """The provenance of a ledger's figures: the full hash of the commit that made them (``git
    rev-parse``), ``+patched`` with a note when something was applied to it."""
    import subprocess

    if not commit:
        raise SystemExit("--record needs --ledger-commit: the ledger's entries name only a fingerprint of "
                         "the code that made them, and a recorded figure names its commit")
    done = subprocess.run(["git", "rev-parse", "--verify", f"{commit}^{{commit}}"], capture_output=True,
                          text=True, check=False, cwd=Path(__file__).resolve().parent)
    if done.returncode != 0:
        raise SystemExit(f"--ledger-commit {commit!r} is not a commit of this repository")
    made = {"commit": done.stdout.strip() + ("+patched" if patch else "")}
    if patch:
        made["note"] = patch
    return made


def report_ledger(ledger: Path, tasks: list[str], draws: int, made: dict[str, str] | None = None) -> None:
    """The table and curves of the ledger's entries for ``tasks``, which must share code and settings;
    a table short of tasks says so first. ``record`` writes the table's figures to
    ``docs/results/policy_table1.json`` (refused for a partial table), stamped with the ledger's code
    fingerprint and the date of its last entry, not with the code that reports it (``made``: the commit
    that made the ledger, from :func:`ledger_made`; None: nothing is recorded)."""
    entries = [e for t in tasks if (e := read_entry(ledger, t, None)) is not None]
    if not entries:
        raise SystemExit(f"{ledger} holds none of the tasks {tasks}")
    stamps = {json.dumps({k: e[k] for k in ("code", "settings")}, sort_keys=True) for e in entries}
    if len(stamps) > 1:
        raise SystemExit(f"{ledger}: its entries come from {len(stamps)} different codes or settings; one "
                         "table comes from one")
    missing = [t for t in tasks if t not in {e["task"] for e in entries}]
    first = entries[0]
    print(f"ledger {ledger}: code {first['code']}, {len(entries)} of {len(tasks)} tasks, written "
          f"{min(e['written'] for e in entries)} to {max(e['written'] for e in entries)}")
    if missing:
        print(f"PARTIAL: not in the ledger yet: {', '.join(missing)}")
    print("settings: " + ", ".join(f"{k}={v}" for k, v in first["settings"].items()))
    for e in entries:
        kinds = e["failure_kinds"]
        if kinds:
            print(f"{e['task']}: what the oracle finds wrong in Vanilla's demos: "
                  + ", ".join(f"{what} in {n}" for what, n in kinds.items()))
    summary = report([r for e in entries for r in e["results"]], {e["task"]: e["noise"] for e in entries},
                     draws)
    curves: dict[tuple[str, str, int], tuple[list[int], list[float]]] = {}
    for e in entries:
        curves |= entry_curves(e)
    path = plot_curves(curves, [e["task"] for e in entries], ledger / "learning_curves.png")
    if path is not None:
        print(f"\nlearning curves: {path}")
    if made is not None:
        if missing:
            raise SystemExit("--record writes whole tables only: the ledger lacks " + ", ".join(missing))
        record_table(entries, summary, made)


def record_table(entries: list[dict[str, Any]], summary: dict[str, Any], made: dict[str, str]) -> None:
    import results

    settings = entries[0]["settings"]
    names = {"vcage": "V-CAGE", "vanilla": "Vanilla"}
    figures = {f"Avg SR {names[m]}": f"{avg:.1%}" for m, avg in summary["avg"].items()}
    if summary["gap"] is not None:
        gap, low, high, _ = summary["gap"]
        figures["V-CAGE - Vanilla gap (paired bootstrap 95%)"] = f"{gap:+.1%} [{low:+.1%}, {high:+.1%}]"
    noise = {e["task"]: e["noise"] for e in entries}
    for task, methods in summary["tasks"].items():
        figures[task] = "; ".join(f"{names[m]} {s}/{n} ({s / n:.1%})" for m, (s, n) in methods.items()) + \
            f"; Vanilla label noise {noise[task]:.0%}"
    path = results.record(
        "policy_table1", "Downstream policy: V-CAGE against Vanilla data (the paper's Table 1)",
        "Does a diffusion policy trained on V-CAGE's verified demonstrations succeed more often on held-out "
        "scenes than one trained on Vanilla's, task by task and on average?",
        figures,
        f"{len(entries)} tasks; per task and method {settings['demos']} demonstrations from one dataset "
        f"draw (generation seed {settings['seed']}), {settings['train_seeds']} training seeds, "
        f"{settings['steps']} steps, {settings['eval']} held-out scenes per seed; the gap's interval "
        "resamples tasks and held-out scenes (training seeds averaged, one dataset draw): it leaves out "
        "the variance of training seeds and of dataset draws",
        made=made | {"code_fingerprint": entries[0]["code"], "date": max(e["written"] for e in entries)[:10]})
    print(f"recorded in {path}")


def train_stage(tasks: list[str], args: argparse.Namespace) -> None:
    """Every pending training run of ``tasks``, on ``--device``; reads the datasets only (no simulator)."""
    runs = [(t, m, s) for t in tasks for m in METHODS for s in range(args.train_seeds)]
    pending = [(t, m, s) for t, m, s in runs if not (run_dir(args.work, t, m, s) / TRAINED).is_file()]
    datasets = {(t, m): dataset_dir(args.work, t, m) for t in tasks for m in METHODS}
    for path in datasets.values():
        if not (path / "meta" / "info.json").is_file():
            raise SystemExit(f"no dataset at {path}: run --stage data first")
    if pending and args.budget is not None:  # the steps that fit the budget, the same for every run
        probes = [(datasets[t, m], run_dir(args.work, t, m, s), train_config(args, s)) for t, m, s in pending]
        args.steps = budget_steps(probes, args.budget, args.work, args.workers, args.threads, args.device,
                                  args.probe_steps, args.cuda_graph)
    jobs = [(datasets[t, m], run_dir(args.work, t, m, s), train_config(args, s)) for t, m, s in pending]
    trained = train_all(jobs, args.workers, args.threads, args.device, args.cuda_graph)
    for (t, m, s), (_, run, config) in zip(pending, jobs, strict=True):
        seconds, rate, loss = trained[run]
        print(f"  {t}: {m:8s} seed {s}: {config.steps} steps in {seconds:.0f} s ({rate:.0f} samples/s, "
              f"batch {config.batch_size}) on {args.device}, final loss {loss:.4f}", flush=True)
    if args.export is not None:
        export_runs(runs, args.work, args.export)


def evaluate_stage(task: str, args: argparse.Namespace, datasets: dict[str, Path],
                   scenes: list[int]) -> list[dict[str, Any]]:
    """Train what is not trained yet (unless only evaluating), then roll every run out."""
    from vcage.data import DatasetReader

    runs = [(task, m, s) for m in METHODS for s in range(args.train_seeds)]
    if args.import_from is not None:
        import_runs(runs, args.work, args.import_from)
    env_config = DatasetReader(datasets["vcage"]).config or {}
    pending = [(m, s) for _, m, s in runs if not result_path(args.work, task, m, s).is_file()
               and trained_record(run_dir(args.work, task, m, s)) is None]
    trained: dict[Path, tuple[float, float, float]] = {}
    if args.stage != "evaluate":
        jobs = [(datasets[m], run_dir(args.work, task, m, s), train_config(args, s)) for m, s in pending]
        trained = train_all(jobs, args.workers, args.threads, args.device, args.cuda_graph)
    results = []
    for _, method, train_seed in runs:
        r = train_and_evaluate(task, method, datasets[method], env_config, scenes, train_seed, args,
                               args.work, trained.get(run_dir(args.work, task, method, train_seed)))
        print(f"  {method:8s} seed {train_seed}: SR {r['success_rate']:.1%} on {r['episodes']} "
              f"scenes, {r['train_samples_per_second']:.0f} training samples/s, "
              f"{r['rollouts_per_minute']:.1f} rollouts/min", flush=True)
        results.append(r)
    return results


if __name__ == "__main__":
    main()
