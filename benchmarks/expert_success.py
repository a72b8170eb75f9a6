"""Scripted-expert success rate per atomic task over N seeds, randomisation off and on.

Scenes are instantiated with the chosen placement method (context-aware by default) and, with
``--clutter N``, N distractors around the task's objects.

    .venv/bin/python benchmarks/expert_success.py --seeds 50 --workers 2
    .venv/bin/python benchmarks/expert_success.py --seeds 50 --workers 2 --clutter 8
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor

from vcage.config import Randomization
from vcage.errors import PlacementError, SimulationError, UnstableSceneError
from vcage.scene.instantiate import SceneConfig
from vcage.scene.placement import PLACERS
from vcage.tasks import TASKS, run_episode


def _one(args: tuple[str, int, bool, SceneConfig]) -> tuple[str, bool, int, bool, str]:
    task, seed, randomized, scene = args
    rand = Randomization() if randomized else Randomization.off()
    try:
        res = run_episode(task, seed, rand, record=False, scene=scene)
        reason = res.skill_error or ("" if res.success else "predicates: " + ",".join(
            k for k, v in res.info.items() if v is False))
        return task, randomized, seed, res.success, reason
    except SimulationError as exc:
        return task, randomized, seed, False, f"unstable: {exc}"
    except PlacementError as exc:
        return task, randomized, seed, False, f"placement: {exc}"
    except UnstableSceneError as exc:
        return task, randomized, seed, False, f"invalid scene: {exc}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seeds", type=int, default=50)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--tasks", nargs="*", default=None)
    parser.add_argument("--placement", default="context", choices=PLACERS.names())
    parser.add_argument("--clutter", type=int, default=0)
    parser.add_argument("--first-seed", type=int, default=0, help="seeds first-seed .. first-seed+seeds-1")
    parser.add_argument("--randomized-only", action="store_true",
                        help="skip the randomisation-off setting (the issue's target is with it on)")
    args = parser.parse_args()
    scene = SceneConfig(args.placement, args.clutter)
    tasks = args.tasks or TASKS.names()
    settings = (True,) if args.randomized_only else (False, True)
    seeds = range(args.first_seed, args.first_seed + args.seeds)
    jobs = [(t, s, r, scene) for t in tasks for r in settings for s in seeds]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as pool:
        results = list(pool.map(_one, jobs, chunksize=4))
    wall = time.perf_counter() - t0
    rates: dict[tuple[str, bool], list[bool]] = {}
    reasons: dict[str, dict[str, int]] = {}
    for task, randomized, _seed, ok, reason in results:
        rates.setdefault((task, randomized), []).append(ok)
        if not ok:
            key = reason.split(":")[0][:60]
            reasons.setdefault(task, {}).setdefault(key, 0)
            reasons[task][key] += 1
    print(f"scripted-expert success over {args.seeds} seeds per task (seeds {seeds.start}.."
          f"{seeds.stop - 1}; {len(jobs)} episodes, "
          f"{wall:.0f} s wall on {args.workers} workers); placement {args.placement}, "
          f"{args.clutter} distractors\n")
    print(f"{'task':28s} {'rand off':>9s} {'rand on':>9s}")
    means: dict[bool, list[float]] = {False: [], True: []}

    def cell(task: str, randomized: bool) -> str:
        if (task, randomized) not in rates:
            return f"{'n/a':>9s}"
        rate = sum(rates[(task, randomized)]) / args.seeds
        means[randomized].append(rate)
        return f"{rate:9.0%}"

    for task in tasks:
        print(f"{task:28s} {cell(task, False)} {cell(task, True)}")

    def summary(values: list[float], fmt: str) -> str:
        return f"{'n/a':>9s}" if not values else format(fmt(values), "9.1%")

    print(f"{'mean':28s} {summary(means[False], lambda v: sum(v) / len(v))} "
          f"{summary(means[True], lambda v: sum(v) / len(v))}")
    print(f"{'minimum':28s} {summary(means[False], min)} {summary(means[True], min)}")
    if reasons:
        print("\nfailure reasons (both settings):")
        for task, counts in sorted(reasons.items()):
            print(f"  {task}: " + "; ".join(f"{k} x{v}" for k, v in sorted(counts.items())))


if __name__ == "__main__":
    main()
