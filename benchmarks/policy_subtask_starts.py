"""Can a policy do a plan's later subtask when it is put where a demonstration began it?

For the first ``--episodes`` episodes of the dataset a checkpoint was trained on, the evaluation
environment builds the episode's scene, sets the simulator state the demonstration had at the first
frame of subtask ``--subtask`` (earlier subtasks counted done) and rolls the policy out from there.
It prints how many episodes complete that subtask and how many the whole plan, and in how many the
earlier subtasks' work is no longer in place at the end (the policy went back to it: a mouse
picked off its pad again). A subtask-conditioned policy also reports the subtask its classifier
named at the first chunk. When the subtask's skill names an object (``obj``) and the observations
carry the tool's pose and the objects' poses, it prints where the hand came lowest: how high above
that object's origin (where it stood when the subtask began) and how far from it across the table,
beside the same for the demonstration (a press that stops short, or lands beside the button).

    LP_NUM_THREADS=1 .venv/bin/python benchmarks/policy_subtask_starts.py RUN --subtask 1 --episodes 20
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import numpy as np


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("checkpoint", type=Path, help="a checkpoint file or a training run's directory")
    parser.add_argument("--dataset", type=Path, default=None,
                        help="the dataset whose demonstrations give the starts (default: the checkpoint's)")
    parser.add_argument("--subtask", type=int, default=1, help="the subtask to start at (0-based)")
    parser.add_argument("--episodes", type=int, default=20, help="demonstrations to start from")
    parser.add_argument("--max-steps", type=int, default=600, help="control steps per episode at most")
    parser.add_argument("--seed", type=int, default=0, help="seed of the sampler's noise")
    args = parser.parse_args()

    import torch

    from vcage.data.reader import DatasetReader
    from vcage.pipeline.evaluation import make_env
    from vcage.pipeline.features import EE_POSE
    from vcage.policy.checkpoint import load_checkpoint
    from vcage.policy.dataset import fingerprint
    from vcage.policy.evaluate import check_compatible
    from vcage.policy.inference import PolicyRunner
    from vcage.policy.rollout import episode_noise_seed

    torch.set_num_threads(1)
    payload = load_checkpoint(args.checkpoint)
    reader = DatasetReader(args.dataset or payload["dataset"]["path"], videos=False)
    # the environment of the dataset that gives the starts: its scene seeds build its own scenes
    env = make_env(reader.config, seed=args.seed, max_steps=args.max_steps,
                   action=payload["action_feature"]["name"])
    check_compatible(payload, env)
    goal = env.unwrapped
    if not 0 < args.subtask < len(goal.plan.subtasks):
        parser.error(f"--subtask must be a later subtask of the plan: 1 to {len(goal.plan.subtasks) - 1}")
    runner = PolicyRunner(payload, seed=args.seed)
    obj = goal.plan.subtasks[args.subtask].args.get("obj")
    done = undone = named_right = started_done = 0
    misses: dict[bool, list[float]] = {True: [], False: []}
    episodes = min(args.episodes, reader.num_episodes)
    steps = []
    for k in range(episodes):
        episode = reader.episode(k)
        extras = episode.extras
        start = extras["subtasks"][args.subtask]["frames"][0]
        runner.reset(episode_noise_seed(args.seed, k))
        obs, info = env.reset(options={"scene_seed": extras["seed"], "subtask": args.subtask,
                                       "state": episode.arrays["states"][start]})
        where = object_position(goal.plan, obs, obj)
        first, t, terminated, truncated = None, 0, False, False
        hand = []
        while not (terminated or truncated):
            obs, _, terminated, truncated, info = env.step(runner.act(obs))
            first = runner.subtask if first is None else first
            t += 1
            if EE_POSE in obs:
                hand.append(np.asarray(obs[EE_POSE], dtype=float)[:3])
        back = not all(goal.holds(j) for j in range(args.subtask))
        done += bool(info["success"])
        started_done += info["subtasks_done"] > args.subtask
        undone += back
        named_right += first == args.subtask
        steps.append(t)
        reach = ""
        if where is not None and hand:
            span = extras["subtasks"][args.subtask]["frames"]
            demo = lowest(np.asarray(episode.frames[EE_POSE], dtype=float)[span[0]:span[1], :3], where)
            ours = lowest(np.array(hand), where)
            misses[bool(info["success"])].append(ours[1])
            reach = (f"; hand lowest {ours[0] * 1000:.0f} mm above the {obj} at ({where[0]:.2f}, "
                     f"{where[1]:.2f}), {ours[1] * 1000:.0f} mm beside it (demo {demo[0] * 1000:.0f}, "
                     f"{demo[1] * 1000:.0f})")
        print(f"  episode {k}: {'completed' if info['success'] else 'not completed'} in {t} steps"
              f"{'; earlier work undone' if back else ''}"
              f"{f'; classifier named subtask {first} first' if runner.model.subtasks else ''}{reach}",
              flush=True)
    own = fingerprint(reader) == payload["dataset"]["fingerprint"]
    whose = "the policy's own training scenes" if own else "not the policy's training data"
    print(f"{payload['path']}")
    print(f"started at subtask {args.subtask} of {len(goal.plan.subtasks)} from {episodes} demonstrations of "
          f"{reader.root} ({whose}): subtask {args.subtask} done in "
          f"{started_done}/{episodes}, plan completed in {done}/{episodes}, earlier work undone in "
          f"{undone}/{episodes}, median {int(np.median(steps))} steps"
          + (f"; classifier named subtask {args.subtask} at the first chunk in {named_right}/{episodes}"
             if runner.model.subtasks else ""))
    for success, values in misses.items():
        if values:
            print(f"{'completed' if success else 'not completed'}: the hand came lowest a median "
                  f"{np.median(values) * 1000:.0f} mm beside the {obj} (range {min(values) * 1000:.0f}-"
                  f"{max(values) * 1000:.0f} mm, {len(values)} starts)")


def object_position(plan: Any, obs: dict[str, Any], obj: str | None) -> np.ndarray | None:
    """The position of ``obj`` in an observation, or None without one (no object, no such feature)."""
    from vcage.pipeline.features import EE_POSE, ENVIRONMENT, pose_slice

    if obj is None or ENVIRONMENT not in obs or EE_POSE not in obs:
        return None
    return np.asarray(obs[ENVIRONMENT], dtype=float)[pose_slice(plan, obj)][:3]


def lowest(hand: np.ndarray, where: np.ndarray) -> tuple[float, float]:
    """Height above ``where`` and distance from it across the table of the lowest of ``hand`` (T, 3)."""
    i = int(np.argmin(hand[:, 2]))
    return float(hand[i, 2] - where[2]), float(np.linalg.norm(hand[i, :2] - where[:2]))


if __name__ == "__main__":
    main()
