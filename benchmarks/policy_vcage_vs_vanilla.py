"""Downstream value of verified data, in the shape of the paper's Table 1: the same policy trained on
V-CAGE data and on Vanilla data of the same tasks and seeds, evaluated on the same held-out scenes.

For each task of the suite (single-subtask instructions and long-horizon goals):

1. generate ``--demos`` episodes with V-CAGE (context-aware placement, scene check, image critic)
   and with Vanilla (naive placement, no check, no critic) on the same run seed;
2. pick ``--eval`` held-out scenes that the scripted expert solves: evaluation scene seeds of the
   V-CAGE dataset's environment (:mod:`vcage.pipeline.evaluation`, disjoint from every generation
   seed) on which the plan's scripted execution succeeds by the oracle;
3. train ``--policy`` on each dataset with each of ``--train-seeds`` seeds and the same budget;
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

Every step is resumable: datasets are completed (``generate(..., total=True)``), training resumes
from its last checkpoint, finished evaluations are read back from ``WORK/results``. ``--quick`` is
the smoke path (one task, two demos, a few training steps, one short evaluation episode): it shows
the loop runs, and its figures mean nothing.

    LP_NUM_THREADS=1 .venv/bin/python benchmarks/policy_vcage_vs_vanilla.py --work /tmp/policy-exp
"""

from __future__ import annotations

import argparse
import functools
import json
import re
import time
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
        root = work / "data" / slug(task) / method
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


def run_dir(work: Path, task: str, method: str, train_seed: int) -> Path:
    return work / "runs" / slug(task) / method / f"seed{train_seed}"


def train_config(args: argparse.Namespace, train_seed: int) -> Any:
    from vcage.policy import TrainConfig

    return TrainConfig(policy=args.policy, steps=args.steps, lr=args.lr, seed=train_seed,
                       checkpoint_every=max(1, min(500, args.steps)))


def train_run(dataset: Path, run: Path, config: Any, threads: int) -> tuple[float, float, float]:
    """One training run (resumed if interrupted): its seconds, samples per second and final loss."""
    from vcage.policy.train import train

    summary = train(dataset, run, config, resume=True, threads=threads, keep=2)  # 20 MB each
    return summary.seconds, summary.samples_per_second, summary.final_loss


def train_all(jobs: list[tuple[Path, Path, Any]], workers: int,
              threads: int) -> dict[Path, tuple[float, float, float]]:
    """The training runs of ``jobs`` (dataset, run directory, config), ``workers`` at a time in
    spawned processes (training is single-threaded at these sizes: processes use the cores)."""
    if workers <= 1 or len(jobs) <= 1:
        return {run: train_run(dataset, run, config, threads) for dataset, run, config in jobs}
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    spawn = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(min(workers, len(jobs)), mp_context=spawn) as pool:
        futures = {run: pool.submit(train_run, dataset, run, config, threads)
                   for dataset, run, config in jobs}
        return {run: future.result() for run, future in futures.items()}


def train_and_evaluate(task: str, method: str, dataset: Path, env_config: dict[str, Any], scenes: list[int],
                       train_seed: int, args: argparse.Namespace, work: Path,
                       trained: tuple[float, float, float] | None = None) -> dict[str, Any]:
    from vcage.pipeline.evaluation import make_env
    from vcage.policy.evaluate import evaluate

    path = result_path(work, task, method, train_seed)
    if path.is_file():
        return dict(json.loads(path.read_text()))
    run = run_dir(work, task, method, train_seed)
    seconds, rate, loss = trained or train_run(dataset, run, train_config(args, train_seed), args.threads)
    evaluation = evaluate(run, len(scenes), seed=0, max_steps=args.max_steps, env_config=env_config,
                          threads=args.threads, make_env=functools.partial(make_env, scenes=scenes),
                          workers=args.workers)
    fit = None
    if args.fit:  # the same checkpoint on scenes of its own training episodes: does it fit its data?
        from vcage.policy.checkpoint import load_checkpoint
        from vcage.policy.evaluate import training_scenes

        own = training_scenes(load_checkpoint(run), args.fit)
        fit = evaluate(run, len(own), seed=0, max_steps=args.max_steps, env_config=env_config,
                       threads=args.threads, scenes=own, workers=args.workers)
    out = evaluation.to_dict() | {"task": task, "method": method, "train_seed": train_seed,
                                  "fit": None if fit is None else {"episodes": len(fit.episodes),
                                                                   "successes": fit.successes},
                                  "train_seconds": seconds, "train_samples_per_second": rate,
                                  "final_loss": loss}
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(out, indent=1))
    return out


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


def report(results: list[dict[str, Any]], noise: dict[str, float], draws: int) -> None:
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
            print(f"{task[:48]:48s} {method:8s} {s / n:6.1%} {f'[{low:.0%}, {high:.0%}]':>15s} {n:5d} "
                  f"{progress:9.2f} {fit:>9s} {noise.get(task, float('nan')):14.1%}")
    print(f"\n{'':14s} {'Avg SR':>8s} {'Top-5 (tasks)':>14s} {'Top-10 (tasks)':>15s} "
          f"{'Top-5 (ckpts)':>14s} {'Top-10 (ckpts)':>15s}")
    for method in METHODS:
        r = rates[method]
        if not r:
            continue
        avg = float(np.mean([np.mean(v) for v in r.values()]))
        cells = [top_k(r, k, how) for how in ("tasks", "checkpoints") for k in (5, 10)]
        shown = ["n/a" if c is None else f"{c:.1%}" for c in cells]
        print(f"{method:14s} {avg:8.1%} {shown[0]:>14s} {shown[1]:>15s} {shown[2]:>14s} {shown[3]:>15s}")
    paired = {t: m for t, m in outcomes.items() if set(m) == set(METHODS)
              and m["vcage"].shape == m["vanilla"].shape}
    if paired:
        gap, low, high = bootstrap_gap(paired, draws, np.random.default_rng(0))
        print(f"\nV-CAGE - Vanilla success gap: {gap:+.1%} (paired bootstrap 95%: [{low:+.1%}, {high:+.1%}], "
              f"{len(paired)} tasks)")
        gaps = [paired[t]["vcage"].mean() - paired[t]["vanilla"].mean() for t in paired]
        noises = [noise.get(t, float("nan")) for t in paired]
        if len(paired) >= 3 and np.std(gaps) > 0 and np.std(noises) > 0:
            corr = np.corrcoef(gaps, noises)[0, 1]
            print(f"correlation of the per-task gap with Vanilla's label noise: {corr:+.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--work", type=Path, required=True, help="directory of datasets, runs and results")
    parser.add_argument("--tasks", nargs="+", default=None, help="instructions (default: the suite)")
    parser.add_argument("--demos", type=int, default=50)
    parser.add_argument("--eval", type=int, default=50, help="held-out scenes per task")
    parser.add_argument("--train-seeds", type=int, default=3)
    parser.add_argument("--policy", choices=("diffusion", "mlp"), default="diffusion")
    parser.add_argument("--steps", type=int, default=15000, help="training steps per checkpoint run")
    parser.add_argument("--lr", type=float, default=1e-3, help="peak learning rate")
    parser.add_argument("--max-steps", type=int, default=None, help="evaluation episode length cap")
    parser.add_argument("--seed", type=int, default=0, help="generation run seed (both methods)")
    parser.add_argument("--size", type=int, default=64, help="video size (the policy is state-based)")
    parser.add_argument("--threads", type=int, default=1, help="torch threads per process")
    parser.add_argument("--workers", type=int, default=1,
                        help="processes for generation, training runs and rollouts (same results as one)")
    parser.add_argument("--fit", type=int, default=10,
                        help="also roll out each checkpoint on this many of its own training scenes (0: no)")
    parser.add_argument("--bootstrap", type=int, default=2000)
    parser.add_argument("--quick", action="store_true", help="smoke path: tiny everything")
    args = parser.parse_args()
    if args.quick:
        args.tasks = args.tasks or list(QUICK_SUITE)
        args.demos, args.eval, args.train_seeds, args.steps = 2, 1, 1, 4
        args.policy, args.max_steps, args.bootstrap, args.fit = "mlp", 20, 50, 1
    tasks = args.tasks or list(SUITE)
    from vcage.pipeline.audit import audit

    results, noise = [], {}
    t0 = time.perf_counter()
    for task in tasks:
        print(f"{task}:", flush=True)
        datasets = make_datasets(task, args.work, args.demos, args.seed, args.size, args.workers)
        noise[task] = audit(datasets["vanilla"]).label_noise
        scenes = solvable_scenes(task, datasets["vcage"], args.work, args.eval, base=1000 + args.seed)
        from vcage.data import DatasetReader

        env_config = DatasetReader(datasets["vcage"]).config or {}
        pending = [(m, s) for m in METHODS for s in range(args.train_seeds)
                   if not result_path(args.work, task, m, s).is_file()]
        jobs = [(datasets[m], run_dir(args.work, task, m, s), train_config(args, s)) for m, s in pending]
        trained = train_all(jobs, args.workers, args.threads)
        for method in METHODS:
            for train_seed in range(args.train_seeds):
                r = train_and_evaluate(task, method, datasets[method], env_config, scenes, train_seed, args,
                                       args.work, trained.get(run_dir(args.work, task, method, train_seed)))
                print(f"  {method:8s} seed {train_seed}: SR {r['success_rate']:.1%} on {r['episodes']} "
                      f"scenes, {r['train_samples_per_second']:.0f} training samples/s, "
                      f"{r['rollouts_per_minute']:.1f} rollouts/min", flush=True)
                results.append(r)
    report(results, noise, args.bootstrap)
    print(f"\n{len(tasks)} tasks, {args.demos} demos per method, {args.train_seeds} training seeds, "
          f"{args.eval} held-out scenes, policy {args.policy} ({args.steps} steps); "
          f"{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
