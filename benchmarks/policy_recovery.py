"""Recovery data against clean data: does a policy trained on verified demos learn more from them?

Question: with the same number of verified (V-CAGE) demonstrations of one task and the same learner,
does a dataset whose expert was pushed off its plan on a share of its motion segments (recovery
data, :mod:`vcage.skills.recovery`: the executed command pushed, the plan's command kept as the
action, the arm's start moved off home) give a policy that succeeds more often on held-out scenes
than a dataset of clean demonstrations?

Two arms from one generation seed (the same attempt seeds): ``clean`` (``GenerateConfig``) and
``recovery`` (the same with ``--fraction``, ``--joint-noise``, ``--start-noise``). Each arm trains
``--train-seeds`` diffusion policies (tool-pose actions, tool pose and object poses observed, as the
Table 1 experiment) and rolls each out on the same held-out scenes (scenes the scripted expert
solves, from seeds disjoint from every generation seed), in the clean arm's environment (the policy
starts at home, as in every evaluation). It prints per arm the successes, the Wilson interval and
the rate per training seed, the training budget in passes over the data, and the recovery - clean
gap with a hierarchical bootstrap 95% interval (training seeds resampled within each arm, then the
held-out scenes, paired across arms): it carries the variance of training seeds and scenes, not of
dataset draws (one generation seed).

    LP_NUM_THREADS=1 .venv/bin/python benchmarks/policy_recovery.py --work /tmp/recovery \\
        --task "put the mouse on the pad" --seed 1 --train-seeds 2

Every stage is resumable in ``--work`` (datasets completed, training resumed, evaluations read back).
"""

from __future__ import annotations

import argparse
import functools
import json
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

import results
from policy_vcage_vs_vanilla import (
    DEFAULT_OBS,
    cached_evaluation,
    slug,
    solvable_scenes,
    train_all,
    trained_record,
    wilson,
)

ARMS = ("clean", "recovery")


def generation_config(arm: str, args: argparse.Namespace) -> Any:
    from vcage.config import RenderConfig
    from vcage.pipeline.config import ExecutorConfig, GenerateConfig
    from vcage.skills.recovery import RecoveryConfig

    cfg = GenerateConfig(seed=args.seed, render=RenderConfig(size=(args.size, args.size), cameras=("front",)),
                         executor=ExecutorConfig(workers=args.workers))
    if arm == "recovery":
        cfg = replace(cfg, recovery=RecoveryConfig(fraction=args.fraction, joint_noise=args.joint_noise,
                                                   start_noise=args.start_noise))
    return cfg


def train_config(args: argparse.Namespace, train_seed: int) -> Any:
    from vcage.policy import TrainConfig

    return TrainConfig(steps=args.steps, seed=train_seed, action_key="action.ee_pose",
                       observation_keys=DEFAULT_OBS, checkpoint_every=min(1000, args.steps))


def run_dir(work: Path, task: str, arm: str, seed: int) -> Path:
    return work / "runs" / slug(task) / arm / f"seed{seed}"


def hierarchical_gap(a: np.ndarray, b: np.ndarray, draws: int, rng: np.random.Generator
                     ) -> tuple[float, float, float]:
    """Mean success of ``a`` minus ``b`` (each (training seeds, scenes), the same scenes) and its
    bootstrap 95% interval: each arm's training seeds resampled, then the scenes (paired)."""
    gap = float(a.mean() - b.mean())
    samples = np.empty(draws)
    for i in range(draws):
        sa = rng.integers(0, a.shape[0], a.shape[0])
        sb = rng.integers(0, b.shape[0], b.shape[0])
        scenes = rng.integers(0, a.shape[1], a.shape[1])
        samples[i] = a[sa][:, scenes].mean() - b[sb][:, scenes].mean()
    low, high = np.percentile(samples, [2.5, 97.5])
    return gap, float(low), float(high)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--work", type=Path, required=True)
    parser.add_argument("--task", default="put the mouse on the pad")
    parser.add_argument("--demos", type=int, default=50)
    parser.add_argument("--eval", type=int, default=50, help="held-out scenes")
    parser.add_argument("--train-seeds", type=int, default=2)
    parser.add_argument("--steps", type=int, default=15000)
    parser.add_argument("--seed", type=int, default=1, help="generation seed (both arms)")
    parser.add_argument("--fraction", type=float, default=0.3, help="share of motion segments pushed")
    parser.add_argument("--joint-noise", type=float, default=0.05, help="rad, per joint, peak of a push")
    parser.add_argument("--start-noise", type=float, default=0.05, help="rad, per joint, off home at start")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--size", type=int, default=64)
    parser.add_argument("--eval-batch", type=int, default=8)
    parser.add_argument("--bootstrap", type=int, default=10000)
    parser.add_argument("--record", action="store_true", help="write the figures to "
                        "docs/results/policy_recovery.json (the results page)")
    args = parser.parse_args()
    from vcage.data import DatasetReader
    from vcage.pipeline.evaluation import make_env
    from vcage.pipeline.generate import generate
    from vcage.policy.evaluate import evaluate

    t0 = time.perf_counter()
    datasets, funnels = {}, {}
    for arm in ARMS:
        root = args.work / "data" / slug(args.task) / arm
        funnel = generate(args.task, args.demos, root, generation_config(arm, args), total=True)
        datasets[arm] = root
        funnels[arm] = DatasetReader(root).num_episodes
        print(f"{arm:9s} {funnels[arm]} demos ({funnel.attempts} attempts this run, "
              f"{funnel.accepted} accepted)", flush=True)
    scenes = solvable_scenes(args.task, datasets["clean"], args.work, args.eval, base=1000 + args.seed)
    jobs = [(datasets[arm], run_dir(args.work, args.task, arm, s), train_config(args, s))
            for arm in ARMS for s in range(args.train_seeds)]
    pending = [job for job in jobs if trained_record(job[1]) is None]
    train_all(pending, args.workers, 1)  # each run writes its record (train.json) when it finishes
    env_config = DatasetReader(datasets["clean"]).config
    outcomes: dict[str, np.ndarray] = {}
    frames = {arm: DatasetReader(datasets[arm]).total_frames for arm in ARMS}
    print(f"\n{args.task}: {len(scenes)} held-out scenes; {args.steps} steps of batch 64 "
          + ", ".join(f"{arm} {args.steps * 64 / frames[arm]:.0f} passes over {frames[arm]} frames"
                      for arm in ARMS))
    print(f"{'arm':9s} {'SR':>6s} {'Wilson 95%':>13s} {'per training seed':>24s} {'final loss':>11s}")
    figures: dict[str, str] = {}
    for arm in ARMS:
        rows = []
        for s in range(args.train_seeds):
            run = run_dir(args.work, args.task, arm, s)
            rows.append(cached_evaluation(run / "evaluation.json", functools.partial(
                evaluate, run, len(scenes), seed=0, env_config=env_config, threads=1,
                make_env=functools.partial(make_env, scenes=scenes), workers=args.workers,
                batch=args.eval_batch)))
        outcomes[arm] = np.array([[e["success"] for e in r["per_episode"]] for r in rows], dtype=float)
        s, n = int(outcomes[arm].sum()), outcomes[arm].size
        low, high = wilson(s, n)
        per_seed = ", ".join(f"{int(o.sum())}/{o.size}" for o in outcomes[arm])
        losses = [json.loads((run_dir(args.work, args.task, arm, k) / "train.json").read_text())["final_loss"]
                  for k in range(args.train_seeds)]
        print(f"{arm:9s} {s / n:6.1%} {f'[{low:.0%}, {high:.0%}]':>13s} {per_seed:>24s} "
              f"{np.mean(losses):11.4f}")
        figures[f"{arm}: success on held-out scenes"] = f"{s}/{n} ({s / n:.1%}; per training seed {per_seed})"
    gap, low, high = hierarchical_gap(outcomes["recovery"], outcomes["clean"], args.bootstrap,
                                      np.random.default_rng(0))
    print(f"\nrecovery - clean: {gap:+.1%} (hierarchical bootstrap 95%: [{low:+.1%}, {high:+.1%}]; training "
          f"seeds, then scenes); {time.perf_counter() - t0:.0f} s")
    figures["recovery - clean (hierarchical bootstrap 95%)"] = f"{gap:+.1%} [{low:+.1%}, {high:+.1%}]"
    if args.record:
        path = results.record(
            "policy_recovery", "Downstream policy: recovery data against clean data",
            "With the same verified demonstrations of one task and the same learner, does recovery data from "
            "the expert (executed commands pushed off the plan, the plan's command kept as the action) raise "
            "the policy's success on held-out scenes?",
            figures,
            f"{args.task!r}: {args.demos} V-CAGE demonstrations per arm from generation seed {args.seed} "
            f"(one dataset draw), recovery {args.fraction} of segments, {args.joint_noise} rad pushes, "
            f"{args.start_noise} rad starts; {args.train_seeds} training seeds per arm, {args.steps} "
            f"steps; {len(scenes)} held-out scenes; the interval carries training seeds and scenes, not "
            "dataset draws")
        print(f"recorded in {path}")


if __name__ == "__main__":
    main()
