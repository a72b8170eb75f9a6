"""Temporal ensembling against chunk execution: the same checkpoints, the same scenes, two ways of acting.

Question: do the policies of an experiment that already ran (``policy_recovery.py`` or
``policy_vcage_vs_vanilla.py``: its ``--work`` directory) succeed more often on their held-out scenes
when they act by temporal ensembling (:mod:`vcage.policy.ensemble`: a chunk predicted every
``--every`` steps, the ``exp(-decay * i)``-weighted mean of the chunks covering each step, ACT's
rule) than when they execute 8 steps of each chunk (the evaluation the experiment made)?

Each run of the chosen arms is rolled out again with ensembling on the experiment's held-out scenes
(its ``eval/TASK.json``) with the same evaluation seed and batch as its stored ``evaluation.json``;
the table pairs the two per checkpoint and prints the ensemble - plain gap with a paired
hierarchical bootstrap 95% interval (checkpoints resampled, then scenes, the same draws for both ways
of acting). With ``--fit N`` both ways are also rolled out on the first N training scenes of each run
(does the policy replay its own demonstrations?). Nothing is retrained; evaluations are cached in
each run directory.

    LP_NUM_THREADS=1 .venv/bin/python benchmarks/policy_ensemble.py --work /tmp/recovery \\
        --task "put the mouse on the pad" --arms clean,recovery --env-arm clean --fit 20 --workers 2
"""

from __future__ import annotations

import argparse
import functools
import json
import time
from pathlib import Path
from typing import Any

import numpy as np

import results
from policy_vcage_vs_vanilla import cached_evaluation, slug, wilson


def paired_gap(a: np.ndarray, b: np.ndarray, draws: int, rng: np.random.Generator
               ) -> tuple[float, float, float]:
    """Mean of ``a`` minus ``b`` (each (checkpoints, scenes), the same checkpoints and scenes) and its
    bootstrap 95% interval: checkpoints resampled, then scenes, both ways of acting drawn alike."""
    gap = float(a.mean() - b.mean())
    samples = np.empty(draws)
    for i in range(draws):
        rows = rng.integers(0, a.shape[0], a.shape[0])
        cols = rng.integers(0, a.shape[1], a.shape[1])
        samples[i] = (a[rows][:, cols] - b[rows][:, cols]).mean()
    low, high = np.percentile(samples, [2.5, 97.5])
    return gap, float(low), float(high)


def successes(record: dict[str, Any]) -> list[float]:
    return [float(e["success"]) for e in record["per_episode"]]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--work", type=Path, required=True, help="the work directory of a policy experiment")
    parser.add_argument("--task", default="put the mouse on the pad")
    parser.add_argument("--arms", default="clean,recovery", help="comma-separated arms of the experiment")
    parser.add_argument("--env-arm", default="clean", help="the arm whose dataset's environment evaluates")
    parser.add_argument("--only", default="seed*", help="the training runs of each arm to use (a glob: "
                        "seed0, seed[01])")
    parser.add_argument("--every", type=int, default=1, help="steps between two predicted chunks")
    parser.add_argument("--decay", type=float, default=0.01, help="ACT's weight exp(-decay * i)")
    parser.add_argument("--fit", type=int, default=0, help="also roll out on this many training scenes")
    parser.add_argument("--batch", type=int, default=8, help="episodes stepped together: the batch of the "
                        "stored evaluations (the experiment's --eval-batch)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--bootstrap", type=int, default=10000)
    parser.add_argument("--record", action="store_true", help="write the figures to "
                        "docs/results/policy_ensemble.json (the results page)")
    args = parser.parse_args()
    from vcage.cli.evaluate import read_scenes
    from vcage.data import DatasetReader
    from vcage.pipeline.evaluation import make_env
    from vcage.policy.checkpoint import load_checkpoint
    from vcage.policy.ensemble import TemporalEnsemble
    from vcage.policy.evaluate import evaluate, training_scenes

    t0 = time.perf_counter()
    task = slug(args.task)
    arms = [a.strip() for a in args.arms.split(",") if a.strip()]
    ensemble = TemporalEnsemble(args.every, args.decay)
    tag = f"ensemble-e{args.every}-d{args.decay:g}"
    scenes = read_scenes(args.work / "eval" / f"{task}.json")
    env_config = DatasetReader(args.work / "data" / task / args.env_arm).config
    runs = sorted(run for arm in arms for run in (args.work / "runs" / task / arm).glob(args.only)
                  if (run / "evaluation.json").is_file())
    if not runs:
        raise SystemExit(f"no evaluated runs of {arms} under {args.work / 'runs' / task}: run the "
                         "experiment first")
    held: dict[str, list[list[float]]] = {"plain": [], "ensemble": []}
    fit: dict[str, list[list[float]]] = {"plain": [], "ensemble": []}
    print(f"{args.task}: {len(runs)} checkpoints, {len(scenes)} held-out scenes; ensembling every "
          f"{args.every} steps, decay {args.decay:g}")
    header = f"{'run':24s} {'plain':>8s} {'ensemble':>9s}"
    print(header + (f" {'fit plain':>10s} {'fit ens.':>9s}" if args.fit else ""))
    for run in runs:
        plain = json.loads((run / "evaluation.json").read_text())
        if len(plain["per_episode"]) != len(scenes):
            raise SystemExit(f"{run}/evaluation.json holds {len(plain['per_episode'])} episodes, the "
                             f"held-out scenes are {len(scenes)}")
        roll = functools.partial(evaluate, run, len(scenes), seed=int(plain["seed"]), env_config=env_config,
                                 threads=1, make_env=functools.partial(make_env, scenes=scenes),
                                 workers=args.workers, batch=args.batch)
        ens = cached_evaluation(run / f"evaluation-{tag}.json", functools.partial(roll, ensemble=ensemble))
        held["plain"].append(successes(plain))
        held["ensemble"].append(successes(ens))
        line = f"{run.parent.name + '/' + run.name:24s} {int(sum(held['plain'][-1])):4d}/{len(scenes):<3d} " \
               f"{int(sum(held['ensemble'][-1])):5d}/{len(scenes):<3d}"
        if args.fit:
            mine = training_scenes(load_checkpoint(run), args.fit)
            fitted = functools.partial(evaluate, run, len(mine), seed=0, env_config=env_config, threads=1,
                                       make_env=functools.partial(make_env, scenes=mine),
                                       workers=args.workers, batch=args.batch)
            for way, extra in (("plain", {}), ("ensemble", {"ensemble": ensemble})):
                name = f"fit{len(mine)}-plain.json" if way == "plain" else f"fit{len(mine)}-{tag}.json"
                fit[way].append(successes(cached_evaluation(run / name, functools.partial(fitted, **extra))))
            line += (f" {int(sum(fit['plain'][-1])):6d}/{len(mine):<3d}"
                     f" {int(sum(fit['ensemble'][-1])):5d}/{len(mine):<3d}")
        print(line, flush=True)
    figures: dict[str, str] = {}
    for name, table in (("held-out", held), ("training scenes", fit)):
        if not table["plain"]:
            continue
        a, b = np.array(table["ensemble"]), np.array(table["plain"])
        for way, x in (("plain", b), ("ensemble", a)):
            s, n = int(x.sum()), x.size
            low, high = wilson(s, n)
            print(f"{name:16s} {way:9s} {s}/{n} = {s / n:.1%} (Wilson [{low:.0%}, {high:.0%}])")
            figures[f"{name}: {way}"] = f"{s}/{n} ({s / n:.1%})"
        gap, low, high = paired_gap(a, b, args.bootstrap, np.random.default_rng(0))
        changed = int((a != b).sum())
        print(f"{name:16s} ensemble - plain: {gap:+.1%} (paired bootstrap 95%: [{low:+.1%}, {high:+.1%}]; "
              f"checkpoints, then scenes); {changed} of {a.size} episodes changed outcome")
        figures[f"{name}: ensemble - plain (paired bootstrap 95%)"] = f"{gap:+.1%} [{low:+.1%}, {high:+.1%}]"
    print(f"{time.perf_counter() - t0:.0f} s")
    if args.record:
        names = [f"{r.parent.name}/{r.name}" for r in runs]
        path = results.record(
            "policy_ensemble", "Downstream policy: temporal ensembling against chunk execution",
            "Do the same checkpoints succeed more often on the same held-out scenes when they act by "
            "temporal ensembling (a chunk every step, ACT's weights) than when they execute 8 steps of each "
            "chunk?",
            figures,
            f"{args.task!r}: {len(runs)} checkpoint(s) ({', '.join(names)} "
            f"of {args.work}), {len(scenes)} held-out scenes, ensembling every {args.every} steps with decay "
            f"{args.decay:g}; the interval carries "
            + ("checkpoints and scenes" if len(runs) > 1 else "scenes only (one checkpoint)")
            + ", not dataset draws")
        print(f"recorded in {path}")


if __name__ == "__main__":
    main()
