"""Where a policy rollout's time goes: the policy's inference against the environment's step.

Rolls a checkpoint out in the evaluation environment of the dataset it was trained on, on one
thread, and prints per control step the milliseconds spent in ``PolicyRunner.act`` (a diffusion
policy samples a chunk with its DDIM steps once every ``n_action_steps`` steps) and in
``env.step`` (physics, control and the oracle's progress), and the environment's reset.

    LP_NUM_THREADS=1 .venv/bin/python benchmarks/policy_rollout.py RUN --episodes 2 --max-steps 400
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("checkpoint", type=Path, help="a checkpoint file or a training run's directory")
    parser.add_argument("--episodes", type=int, default=2)
    parser.add_argument("--max-steps", type=int, default=400, help="control steps per episode at most")
    parser.add_argument("--seed", type=int, default=0, help="evaluation seed")
    parser.add_argument("--compare-batch", type=int, default=0,
                        help="also evaluate --episodes episodes with vcage's evaluate at batch 1 and at "
                             "this batch, and compare rollouts per minute and outcomes (0: no)")
    parser.add_argument("--batch-sizes", type=int, nargs="*", default=[1, 8, 32],
                        help="also time the policy's network alone at these batch sizes (what sampling "
                             "several episodes' chunks at once would cost)")
    args = parser.parse_args()

    import torch

    from vcage.pipeline.evaluation import make_env
    from vcage.policy.checkpoint import load_checkpoint
    from vcage.policy.inference import PolicyRunner
    from vcage.policy.rollout import episode_noise_seed

    torch.set_num_threads(1)
    checkpoint = load_checkpoint(args.checkpoint)
    env = make_env(checkpoint["dataset"]["config"], max_steps=args.max_steps,
                   action=checkpoint["action_feature"]["name"])
    runner = PolicyRunner(checkpoint)
    policy = stepping = resetting = 0.0
    steps = 0
    for episode in range(args.episodes):
        runner.reset(episode_noise_seed(args.seed, episode))
        t = time.perf_counter()
        obs, _ = env.reset(seed=args.seed, options={"episode": episode})
        resetting += time.perf_counter() - t
        done = False
        while not done:
            t0 = time.perf_counter()
            action = runner.act(obs)
            t1 = time.perf_counter()
            obs, _, terminated, truncated, _ = env.step(action)
            stepping += time.perf_counter() - t1
            policy += t1 - t0
            steps += 1
            done = terminated or truncated
    config = checkpoint["config"]
    total = policy + stepping + resetting
    print(f"{args.episodes} episodes, {steps} control steps, policy {config['policy']} "
          f"(step {checkpoint['step']}, down_dims {config['diffusion']['down_dims']}, "
          f"{config['diffusion']['inference_steps']} DDIM steps per chunk of {config['n_action_steps']})")
    print(f"  policy  {1000 * policy / steps:6.2f} ms per control step ({policy / total:.0%})")
    print(f"  env     {1000 * stepping / steps:6.2f} ms per control step ({stepping / total:.0%})")
    print(f"  reset   {resetting / args.episodes:6.2f} s per episode ({resetting / total:.0%})")
    if args.batch_sizes and config["policy"] == "diffusion":
        network_passes(runner, args.batch_sizes)
    if args.compare_batch:
        compare_batch(args.checkpoint, args.episodes, args.max_steps, args.seed, args.compare_batch)


def compare_batch(checkpoint: Path, episodes: int, max_steps: int, seed: int, batch: int) -> None:
    """The same episodes evaluated one at a time and in blocks of ``batch``, in one process."""
    from vcage.policy.evaluate import evaluate

    runs = {b: evaluate(checkpoint, episodes, seed=seed, max_steps=max_steps, threads=1, batch=b)
            for b in (1, batch)}
    for b, run in runs.items():
        print(f"  evaluate --batch {b:2d}: {run.rollouts_per_minute:6.1f} rollouts/min, "
              f"{run.successes}/{len(run.episodes)} successes, mean progress {run.mean_progress:.2f}")
    same = sum(a == b for a, b in zip(runs[1].episodes, runs[batch].episodes, strict=True))
    print(f"  {same} of {episodes} episodes identical (steps, subtasks, outcome) at batch 1 and {batch}; "
          f"speed-up {runs[batch].rollouts_per_minute / runs[1].rollouts_per_minute:.2f}x")


def network_passes(runner: Any, sizes: list[int], repeats: int = 50) -> None:
    """Milliseconds per U-Net pass, and per sample, at each batch size (random inputs)."""
    import torch

    unet = runner.model.unet
    horizon, action_dim = runner.config.horizon, runner.model.action_dim
    cond_dim = runner.encoder.size * runner.config.n_obs_steps
    generator = torch.Generator().manual_seed(0)
    for size in sizes:
        x = torch.randn(size, horizon, action_dim, generator=generator)
        t = torch.randint(0, 100, (size,), generator=generator)
        cond = torch.randn(size, cond_dim, generator=generator)
        with torch.no_grad():
            for _ in range(5):
                unet(x, t, cond)
            start = time.perf_counter()
            for _ in range(repeats):
                unet(x, t, cond)
            ms = 1000 * (time.perf_counter() - start) / repeats
        print(f"  network alone, batch {size:3d}: {ms:6.2f} ms per pass, {ms / size:6.3f} ms per sample")


if __name__ == "__main__":
    main()
