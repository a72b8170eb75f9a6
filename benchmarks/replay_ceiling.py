"""The ceiling of a policy's fit: each demonstration's recorded actions replayed, open loop, on its own
scene in the evaluation environment.

A policy rolled out on its training scenes ("fit", ``vcage evaluate --training-scenes``) can at best
do what replaying its demonstrations does. Joint targets (``action``) replay the expert's command;
tool poses (``action.ee_pose``) go through the environment's differential IK, which may put the elbow
elsewhere than the demonstration did, so their replay can fail where the joints' does not. Prints,
per action feature, the episodes whose replay succeeds, their Wilson interval, and the episodes that
fail; ``--record`` writes the counts to a JSON file.

    LP_NUM_THREADS=1 .venv/bin/python benchmarks/replay_ceiling.py DATASET [--episodes N] [--record F]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from policy_vcage_vs_vanilla import wilson


def replay(dataset: Path, action: str, episodes: int) -> tuple[list[int], list[int]]:
    """(episodes whose replay of ``action`` succeeds, episodes whose replay fails)."""
    from vcage.data import DatasetReader
    from vcage.pipeline.evaluation import make_env

    reader = DatasetReader(dataset)
    env = make_env(reader.config or {}, seed=0, action=action)
    won, lost = [], []
    for k in range(min(episodes, reader.num_episodes)):
        ep = reader.episode(k)
        if action not in ep.frames:
            raise SystemExit(f"{dataset} has no {action} column (vcage backfill adds action.ee_pose)")
        env.reset(options={"scene_seed": int(ep.extras["seed"])})
        info: dict = {}
        for act in np.asarray(ep.frames[action]):
            _, _, terminated, truncated, info = env.step(act)
            if terminated or truncated:
                break
        (won if info.get("success") else lost).append(k)
    env.close()
    return won, lost


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("dataset", type=Path)
    parser.add_argument("--episodes", type=int, default=1000, help="the first N episodes (default: all)")
    parser.add_argument("--actions", nargs="+", default=["action", "action.ee_pose"])
    parser.add_argument("--record", type=Path, help="write the counts to this JSON file")
    args = parser.parse_args()
    record: dict = {"dataset": str(args.dataset), "replays": {}}
    for action in args.actions:
        t0 = time.perf_counter()
        won, lost = replay(args.dataset, action, args.episodes)
        n = len(won) + len(lost)
        low, high = wilson(len(won), n)
        print(f"{action:16s} {len(won)}/{n} replays succeed ({len(won) / n:.0%}, Wilson 95% [{low:.0%}, "
              f"{high:.0%}]); failed episodes: {lost or 'none'}; {time.perf_counter() - t0:.0f} s",
              flush=True)
        record["replays"][action] = {"successes": len(won), "episodes": n, "failed": lost}
    if args.record:
        args.record.write_text(json.dumps(record, indent=1) + "\n")


if __name__ == "__main__":
    main()
