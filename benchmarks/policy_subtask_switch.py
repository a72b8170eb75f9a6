"""When does a subtask-conditioned policy's classifier move on, against when the oracle counts a subtask done?

Rolls a subtask-conditioned checkpoint out on held-out scenes (a list of scene seeds, as the
experiment's ``eval/TASK.json`` holds them under ``solved``), one episode at a time, in the
evaluation environment of the dataset it was trained on. For each episode it records the step at
which the oracle first counted each subtask done and the step at which the runner's classifier
first named each later subtask. It prints, for every subtask but the last: the episodes that did it,
those of them after which the classifier moved on and how many of those then did the next subtask,
those after which it never moved on, and the episodes in which it moved on although the subtask
was never done. When the subtask's skill names an object with a target (``obj`` and ``target``)
it also prints how far the object lay from the target's centre at the end, for the episodes whose
classifier never moved on.

    LP_NUM_THREADS=1 .venv/bin/python benchmarks/policy_subtask_switch.py RUN \
        --scenes W/eval/TASK.json --episodes 50
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("checkpoint", type=Path, help="a checkpoint file or a training run's directory")
    parser.add_argument("--scenes", type=Path, required=True,
                        help="a JSON file of held-out scene seeds (a list, or an object whose 'solved' "
                        "is one)")
    parser.add_argument("--episodes", type=int, default=50)
    parser.add_argument("--max-steps", type=int, default=None, help="control steps per episode at most")
    parser.add_argument("--seed", type=int, default=0, help="seed of the sampler's noise")
    args = parser.parse_args()

    import torch

    from vcage.pipeline.evaluation import make_env
    from vcage.policy.checkpoint import load_checkpoint
    from vcage.policy.inference import PolicyRunner
    from vcage.policy.rollout import episode_noise_seed

    torch.set_num_threads(1)
    payload = load_checkpoint(args.checkpoint)
    runner = PolicyRunner(payload, seed=args.seed)
    if not runner.model.subtasks:
        parser.error("the checkpoint is not subtask-conditioned: it has no classifier to follow")
    listed = json.loads(args.scenes.read_text())
    scenes = [int(s) for s in (listed["solved"] if isinstance(listed, dict) else listed)][:args.episodes]
    env = make_env(payload["dataset"]["config"], seed=args.seed, max_steps=args.max_steps,
                   action=payload["action_feature"]["name"])
    plan = env.unwrapped.plan
    n = len(plan.subtasks)
    done_at: list[list[int | None]] = []
    moved_at: list[list[int | None]] = []
    apart: list[list[float | None]] = []
    for k, scene in enumerate(scenes):
        runner.reset(episode_noise_seed(args.seed, k))
        obs, info = env.reset(options={"scene_seed": scene})
        done: list[int | None] = [None] * n
        moved: list[int | None] = [None] * n
        t, terminated, truncated = 0, False, False
        while not (terminated or truncated):
            obs, _, terminated, truncated, info = env.step(runner.act(obs))
            t += 1
            for j in range(min(int(info.get("subtasks_done", 0)), n)):
                done[j] = t if done[j] is None else done[j]
            for j in range(1, runner.subtask + 1):
                moved[j] = t if moved[j] is None else moved[j]
        done_at.append(done)
        moved_at.append(moved)
        apart.append([distance(plan, obs, s.args) for s in plan.subtasks])
        print(f"  scene {k}: {int(info.get('subtasks_done', 0))}/{n} subtasks in {t} steps; done at "
              f"{done}, classifier moved on at {moved[1:]}", flush=True)
    print(f"{payload['path']}: {len(scenes)} held-out scenes")
    for j in range(n - 1):
        did = [e for e in range(len(scenes)) if done_at[e][j] is not None]
        on = [e for e in did if moved_at[e][j + 1] is not None]
        stuck = [e for e in did if moved_at[e][j + 1] is None]
        early = [e for e in range(len(scenes)) if done_at[e][j] is None and moved_at[e][j + 1] is not None]
        followed = sum(done_at[e][j + 1] is not None for e in on)
        gaps = [apart[e][j] for e in stuck if apart[e][j] is not None]
        where = f" (the object {min(gaps) * 1000:.0f}-{max(gaps) * 1000:.0f} mm from its target's centre)" \
            if gaps else ""
        print(f"subtask {j} ({plan.subtasks[j].description}): done in {len(did)}; the classifier moved on "
              f"after {len(on)} of them, and subtask {j + 1} followed in {followed}; never moved on after "
              f"{len(stuck)}{where}; moved on without it in {len(early)}")


def distance(plan: Any, obs: dict[str, Any], args: dict[str, Any]) -> float | None:
    """How far the subtask's object lies from its target's centre across the table (None: no such pair)."""
    from vcage.pipeline.features import ENVIRONMENT, pose_slice

    obj, target = args.get("obj"), args.get("target")
    if not obj or not target or ENVIRONMENT not in obs:
        return None
    state = np.asarray(obs[ENVIRONMENT], dtype=float)
    return float(np.linalg.norm(state[pose_slice(plan, obj)][:2] - state[pose_slice(plan, target)][:2]))


if __name__ == "__main__":
    main()
