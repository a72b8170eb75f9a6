"""Success against training: every kept checkpoint of a training run rolled out on the same scenes.

Question: does the policy's success on held-out scenes still rise at the end of its budget (train
longer), or did it level off or fall earlier (the budget is not what holds it back)? A run keeps all
its checkpoints unless ``--keep-checkpoints`` was given (``vcage train`` keeps all by default; the
experiment scripts keep two). Each checkpoint is evaluated like ``vcage evaluate CHECKPOINT``, on
the run's dataset environment (or ``--env``), on ``--scenes`` (a JSON list of scene seeds, or an
experiment's ``eval/TASK.json``), ``--training-scenes`` (the scenes of the run's own training episodes:
the fit) or the environment's own held-out scenes, with the same evaluation
seed and batch for every checkpoint, so that the rows differ only in the weights. It prints, per
checkpoint, the step, the passes over the data, the successes and their Wilson interval; a
checkpoint's evaluation is cached beside it (``step-N.eval-<tag>.json``). With several runs (e.g.
training seeds) it prints their rows side by side and the pooled rate per step.

    LP_NUM_THREADS=1 .venv/bin/python benchmarks/policy_curve.py runs/mouse-seed0 runs/mouse-seed1 \\
        --scenes work/eval/put_the_mouse_on_the_pad.json --episodes 50 --workers 2
"""

from __future__ import annotations

import argparse
import functools
import re
import time
from pathlib import Path

from policy_vcage_vs_vanilla import cached_evaluation, wilson


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("runs", type=Path, nargs="+", help="training run directories (vcage train --out)")
    parser.add_argument("--scenes", type=Path, help="scene seeds to roll out on (default: held-out scenes)")
    parser.add_argument("--training-scenes", action="store_true",
                        help="roll out on each run's own training scenes (the fit) instead")
    parser.add_argument("--episodes", type=int, default=50)
    parser.add_argument("--seed", type=int, default=0, help="evaluation seed")
    parser.add_argument("--env", type=Path, help="evaluate in this dataset's environment")
    parser.add_argument("--every", type=int, default=1,
                        help="evaluate every k-th kept checkpoint (and the last)")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--batch", type=int, default=8)
    args = parser.parse_args()
    from vcage.cli.evaluate import read_scenes
    from vcage.data import DatasetReader
    from vcage.pipeline.evaluation import make_env
    from vcage.policy.checkpoint import NAME, checkpoints, load_checkpoint
    from vcage.policy.evaluate import evaluate, training_scenes

    if args.training_scenes and args.scenes:
        raise SystemExit("--training-scenes and --scenes choose the scenes two ways: give one")
    t0 = time.perf_counter()
    given = read_scenes(args.scenes) if args.scenes else None
    env_config = DatasetReader(args.env).config if args.env else None
    name = args.scenes.stem if args.scenes else "training" if args.training_scenes else "held-out"
    table: dict[int, dict[int, tuple[int, int]]] = {}  # step -> run index -> (successes, episodes)
    passes: dict[int, float] = {}
    for index, run in enumerate(args.runs):
        found = checkpoints(run)
        if not found:
            raise SystemExit(f"{run} holds no checkpoint: pass a vcage train --out directory")
        chosen = found[::args.every] + ([found[-1]] if (len(found) - 1) % args.every else [])
        # a run's batch and dataset are those of its first checkpoint (resuming changes only the steps)
        first = load_checkpoint(found[0])
        per_step = int(first["config"]["batch_size"]) / int(first["dataset"]["frames"])
        scenes = training_scenes(first, args.episodes) if args.training_scenes else given
        episodes = min(args.episodes, len(scenes)) if scenes else args.episodes
        factory = functools.partial(make_env, scenes=scenes) if scenes else None
        tag = re.sub(r"[^A-Za-z0-9]+", "-", f"{name}-n{episodes}-s{args.seed}-b{args.batch}")
        for path in chosen:
            cache = path.with_name(f"{path.stem}.eval-{tag}.json")
            record = cached_evaluation(cache, functools.partial(
                evaluate, path, episodes, seed=args.seed, env_config=env_config, threads=1, make_env=factory,
                workers=args.workers, batch=args.batch))
            named = NAME.match(path.name)
            assert named is not None  # checkpoints() lists only the files its pattern names
            step = int(named.group(1))
            passes[step] = step * per_step
            table.setdefault(step, {})[index] = (int(record["successes"]), int(record["episodes"]))
            print(f"{run.name}: step {step} {record['successes']}/{record['episodes']}", flush=True)
    print(f"\n{'step':>7s} {'passes':>7s} " + " ".join(f"{r.name[-12:]:>12s}" for r in args.runs)
          + f" {'pooled':>9s} {'Wilson 95%':>13s}")
    for step in sorted(table):
        cells = table[step]
        s, n = sum(c[0] for c in cells.values()), sum(c[1] for c in cells.values())
        low, high = wilson(s, n)
        row = " ".join(f"{f'{cells[i][0]}/{cells[i][1]}' if i in cells else '-':>12s}"
                       for i in range(len(args.runs)))
        print(f"{step:7d} {passes[step]:7.1f} {row} {s / n:9.1%} {f'[{low:.0%}, {high:.0%}]':>13s}")
    print(f"{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
