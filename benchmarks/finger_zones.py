"""Wasted attempts with and without finger zones in context-aware placement, on the same seeds.

An attempt is wasted when it costs physics (and, in generation, critic time) but yields no
episode. This benchmark runs every goal's offline plan with the scripted skills and no critic,
once with finger zones (the default: no footprint where the open fingers go down to grasp a task
object) and once without, on the same attempt seeds, and counts per setting: layouts that could
not be placed (cheap, no physics), scenes that failed the physics check, attempts whose skills
could not plan, and attempts the oracle says failed (the ones a critic must catch or that become
label noise). Each failed attempt's first failed subtask is listed.

    LP_NUM_THREADS=1 .venv/bin/python benchmarks/finger_zones.py --seeds 10 --workers 2
"""

from __future__ import annotations

import argparse
import os
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from typing import Any

from vcage.pipeline import episode as episode_module
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.stage import Stage
from vcage.planning import make_planner
from vcage.planning.goals import GOALS
from vcage.scene.instantiate import SceneConfig
from vcage.scene.placement.base import PlacementConfig

SETTINGS = {"finger zones": True, "none (before)": False}


def _one(job: tuple[str, int, int, int, bool]) -> dict[str, Any]:
    goal, index, run_seed, clutter, zones = job
    phrase = next(g for g in GOALS if g.name == goal).phrasings[0]
    scene = SceneConfig(clutter=clutter, placement_config=PlacementConfig(finger_zones=zones))
    cfg = GenerateConfig(seed=run_seed, critic=None, scene=scene)
    plan = make_planner(cfg.planner).plan(phrase)
    t0 = time.perf_counter()
    result = episode_module.attempt(plan, cfg.episode_seed(index, 0), cfg, None)
    failed = ""
    if result.rollout is not None:
        bad = next((o for o in result.rollout.outcomes if not o.oracle_success), None)
        if bad is not None:
            missed = [k for k, v in bad.oracle.items() if not v]
            failed = f"subtask {bad.index + 1} ({bad.skill}): {', '.join(missed)}"
    return {"goal": goal, "seed": index, "zones": zones, "stage": str(result.stage),
            "reason": result.reason[:90], "success": result.oracle_success, "failed": failed,
            "seconds": time.perf_counter() - t0, "physics": result.timing.physics}


def _pct(a: int, n: int) -> str:
    return f"{a}/{n} ({a / n:.1%})" if n else "n/a"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=10, help="scenes per goal")
    parser.add_argument("--goals", nargs="*", default=[g.name for g in GOALS])
    parser.add_argument("--clutter", type=int, default=4, help="distractors per scene")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=0, help="the run seed the scenes derive from")
    args = parser.parse_args()
    jobs = [(g, i, args.seed, args.clutter, zones) for i in range(args.seeds) for g in args.goals
            for zones in SETTINGS.values()]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as pool:
        rows = list(pool.map(_one, jobs))
    wall = time.perf_counter() - t0
    load = os.getloadavg()
    n_scenes = args.seeds * len(args.goals)
    print(f"{n_scenes} attempt seeds ({args.seeds} per goal x {len(args.goals)} goals), {args.clutter} "
          f"distractors, scripted skills, no critic; {wall:.0f} s wall on {args.workers} workers, "
          f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}\n")
    print(f"{'placement':16s} {'not placed':>12s} {'scene check':>12s} {'skill fail':>10s} "
          f"{'executed':>9s} {'oracle success':>16s} {'wasted (all)':>16s} {'s/attempt':>9s}")
    for label, zones in SETTINGS.items():
        mine = [r for r in rows if r["zones"] == zones]
        stages = Counter(r["stage"] for r in mine)
        executed = [r for r in mine if r["stage"] not in (str(Stage.PLACEMENT), str(Stage.SCENE),
                                                          str(Stage.SKILL))]
        ok = sum(r["success"] for r in executed)
        wasted = len(mine) - sum(r["success"] for r in mine)
        print(f"{label:16s} {stages[str(Stage.PLACEMENT)]:12d} {stages[str(Stage.SCENE)]:12d} "
              f"{stages[str(Stage.SKILL)]:10d} {len(executed):9d} {_pct(ok, len(executed)):>16s} "
              f"{_pct(wasted, len(mine)):>16s} {sum(r['seconds'] for r in mine) / len(mine):9.2f}")
    print("\nper goal, oracle success / executed attempts:")
    print(f"{'goal':24s}" + "".join(f"{label:>18s}" for label in SETTINGS))
    for goal in args.goals:
        cells = []
        for zones in SETTINGS.values():
            mine = [r for r in rows if r["zones"] == zones and r["goal"] == goal and r["stage"] not in
                    (str(Stage.PLACEMENT), str(Stage.SCENE), str(Stage.SKILL))]
            cells.append(_pct(sum(r["success"] for r in mine), len(mine)))
        print(f"{goal:24s}" + "".join(f"{c:>18s}" for c in cells))
    print("\nattempts that yielded no success (setting: goal seed, stage, first failed subtask or reason):")
    for label, zones in SETTINGS.items():
        for r in rows:
            if r["zones"] == zones and not r["success"]:
                print(f"  {label}: {r['goal']} {r['seed']}, {r['stage']}, {r['failed'] or r['reason']}")


if __name__ == "__main__":
    main()
