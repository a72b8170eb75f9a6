"""What each physics setting buys and costs on the plan scenes with clutter, against the defaults.

For a fixed set of seeds on long-horizon goals (offline plans, context-aware placement with 4
distractors, randomisation on, as ``GenerateConfig()``), every scene is instantiated and the
scripted plan executed without a critic (``vcage.pipeline.episode.attempt`` with ``critic=None``)
once per candidate setting. The settings change the physics, so each runs the real execution, not
a replay. Printed per setting, against the first (the defaults before this benchmark: noslip 3,
elliptic cone, 100 solver iterations, tolerance 1e-8) measured in the same run on the same scenes:
control steps per second of the robot's execution (its physics only) and the ratio to the first;
the scene-check pass rate (scenes that settled valid / scenes placed); scripted success (the
oracle: every subtask's predicates held) out of the scenes that passed the check; the scenes
whose check or scripted outcome differs from the first's ("differ"); and where a physics step's
time goes (MuJoCo's timers: collision, constraint construction and projection, solver).

    LP_NUM_THREADS=1 .venv/bin/python benchmarks/physics_settings.py --seeds 10 --workers 2

A setting is applied to the compiled model (``model.opt``) right after composition, so the scene,
its placement and the plan are the same for every setting; ``timestep`` changes ``SimConfig``.
Jobs are one scene each, running every setting back to back, so the ratios compare like with like
on a shared machine.
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from typing import Any

os.environ.setdefault("LP_NUM_THREADS", "1")

from vcage.config import SimConfig  # noqa: E402
from vcage.pipeline import episode as episode_module  # noqa: E402
from vcage.pipeline.config import GenerateConfig  # noqa: E402
from vcage.pipeline.stage import Stage  # noqa: E402
from vcage.planning import make_planner  # noqa: E402
from vcage.planning.goals import GOALS  # noqa: E402
from vcage.scene import compose as compose_module  # noqa: E402
from vcage.scene import instantiate as instantiate_module  # noqa: E402

DEFAULT_GOALS = ("get_ready_for_work", "prepare_breakfast", "tidy_the_desk")
BASE = {"noslip_iterations": 3, "cone": "elliptic", "impratio": 10.0, "iterations": 100,
        "tolerance": 1e-8, "ls_iterations": 50, "sleep": False}


@dataclass(frozen=True)
class Setting:
    name: str
    options: dict[str, Any]
    timestep: float = 0.002


SETTINGS = (
    Setting("noslip 3 (default before)", {}),
    Setting("noslip 1", {"noslip_iterations": 1}),
    Setting("noslip 0 (the default now)", {"noslip_iterations": 0}),
    Setting("iterations 20, tol 1e-6", {"iterations": 20, "tolerance": 1e-6, "ls_iterations": 20}),
    Setting("pyramidal cone", {"cone": "pyramidal"}),
    Setting("pyramidal, noslip 0", {"cone": "pyramidal", "noslip_iterations": 0}),
    Setting("sleep (resting bodies)", {"sleep": True}),
    Setting("noslip 1, sleep", {"noslip_iterations": 1, "sleep": True}),
    Setting("noslip 0, sleep", {"noslip_iterations": 0, "sleep": True}),
    Setting("pyramidal, noslip 0, sleep", {"cone": "pyramidal", "noslip_iterations": 0, "sleep": True}),
    Setting("timestep 2.5 ms", {}, 0.0025),
)


def _apply(model: Any, options: dict[str, Any]) -> None:
    import mujoco  # after vcage chose the GL platform

    opts = {**BASE, **options}
    opt = model.opt
    opt.noslip_iterations = opts["noslip_iterations"]
    cone = mujoco.mjtCone.mjCONE_ELLIPTIC if opts["cone"] == "elliptic" else mujoco.mjtCone.mjCONE_PYRAMIDAL
    opt.cone, opt.impratio = int(cone), opts["impratio"]
    opt.iterations, opt.tolerance = opts["iterations"], opts["tolerance"]
    opt.ls_iterations = opts["ls_iterations"]
    sleep = int(mujoco.mjtEnableBit.mjENBL_SLEEP)
    opt.enableflags = (opt.enableflags | sleep) if opts["sleep"] else (opt.enableflags & ~sleep)


def _patched_compose(options: dict[str, Any]) -> Callable[..., Any]:
    original = compose_module.compose

    def compose(*args: Any, **kwargs: Any) -> Any:
        composed = original(*args, **kwargs)
        _apply(composed.model, options)  # the cached model too: every setting sets every option
        return composed

    return compose


TIMERS = {"collision": ("mjTIMER_POS_COLLISION",),
          "make+project": ("mjTIMER_POS_MAKE", "mjTIMER_POS_PROJECT"), "solver": ("mjTIMER_CONSTRAINT",)}


def _one(job: tuple[str, int, int]) -> list[dict[str, Any]]:
    import mujoco

    goal, index, run_seed = job
    phrase = next(g for g in GOALS if g.name == goal).phrasings[0]
    rows = []
    for setting in SETTINGS:
        cfg = GenerateConfig(seed=run_seed, critic=None, sim=SimConfig(timestep=setting.timestep))
        plan = make_planner(cfg.planner).plan(phrase)
        patched = _patched_compose(setting.options)
        episode_module.compose, instantiate_module.compose = patched, patched  # type: ignore[attr-defined]
        result = episode_module.attempt(plan, cfg.episode_seed(index, 0), cfg, None)
        row = {"goal": goal, "seed": index, "setting": setting.name, "stage": str(result.stage),
               "reason": result.reason[:80], "success": result.oracle_success,
               "steps": 0, "physics": result.timing.physics, "timers": {}}
        if result.recording is not None and result.world is not None:
            world = result.world
            row["steps"] = len(result.recording)  # control steps
            timer = world.data.timer
            row["timers"] = {k: sum(timer[int(getattr(mujoco.mjtTimer, n))].duration for n in names)
                             for k, names in TIMERS.items()}
            row["timers"]["step"] = timer[int(mujoco.mjtTimer.mjTIMER_STEP)].duration
            row["ncon"] = int(world.data.ncon)
        rows.append(row)
    return rows


def _pct(a: int, n: int) -> str:
    return f"{a}/{n} ({a / n:.0%})" if n else "-"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seeds", type=int, default=10, help="scenes per goal")
    parser.add_argument("--goals", nargs="*", default=list(DEFAULT_GOALS))
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=0, help="the run seed the scenes derive from")
    args = parser.parse_args()
    jobs = [(g, i, args.seed) for i in range(args.seeds) for g in args.goals]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as pool:
        rows = [r for rs in pool.map(_one, jobs) for r in rs]
    wall = time.perf_counter() - t0
    load = os.getloadavg()
    print(f"{len(jobs)} scenes ({args.seeds} seeds x {len(args.goals)} goals: {', '.join(args.goals)}), "
          f"4 distractors, no critic, {len(SETTINGS)} settings each; {wall:.0f} s wall on {args.workers} "
          f"workers, load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}\n")
    base_name = SETTINGS[0].name
    by = {(r["setting"], r["goal"], r["seed"]): r for r in rows}
    base_rate = _rate([r for r in rows if r["setting"] == base_name])
    print(f"{'setting':28s} {'ctrl/s':>7s} {'x dflt':>6s} {'scene check ok':>14s} {'differ':>6s} "
          f"{'scripted success':>16s} {'differ':>6s}  {'collide':>7s} {'make+proj':>9s} {'solver':>6s}")
    for setting in SETTINGS:
        mine = [r for r in rows if r["setting"] == setting.name]
        placed = [r for r in mine if r["stage"] != Stage.PLACEMENT]
        checked = [r for r in placed if r["stage"] != Stage.SCENE]
        ok = sum(r["success"] for r in checked)
        base = [by[(base_name, r["goal"], r["seed"])] for r in mine]
        pairs = list(zip(mine, base, strict=True))
        scene_differ = sum((r["stage"] == Stage.SCENE) != (b["stage"] == Stage.SCENE) for r, b in pairs)
        differ = sum(r["success"] != b["success"] for r, b in pairs)
        rate = _rate(mine)
        step = sum(r["timers"].get("step", 0.0) for r in mine) or 1.0
        shares = [sum(r["timers"].get(k, 0.0) for r in mine) / step for k in TIMERS]
        print(f"{setting.name:28s} {rate:7,.0f} {rate / base_rate:6.2f} "
              f"{_pct(len(checked), len(placed)):>14s} {scene_differ:6d} "
              f"{_pct(ok, len(checked)):>16s} {differ:6d}  "
              f"{shares[0]:7.0%} {shares[1]:9.0%} {shares[2]:6.0%}")
    print("\nper goal, scripted success / scenes that passed the check:")
    print(f"{'setting':30s}" + "".join(f"{g[:20]:>22s}" for g in args.goals))
    for setting in SETTINGS:
        cells = []
        for goal in args.goals:
            mine = [r for r in rows if r["setting"] == setting.name and r["goal"] == goal
                    and r["stage"] not in (Stage.PLACEMENT, Stage.SCENE)]
            cells.append(_pct(sum(r["success"] for r in mine), len(mine)))
        print(f"{setting.name:30s}" + "".join(f"{c:>22s}" for c in cells))
    failures = [r for r in rows if not r["success"]]
    if failures:
        print("\nfailures (setting: goal seed stage reason):")
        for r in failures:
            print(f"  {r['setting']}: {r['goal']} {r['seed']} {r['stage']} {r['reason']}")


def _rate(rows: list[dict[str, Any]]) -> float:
    """Control steps per second of physics in the robot's execution, over the executed scenes."""
    steps = sum(r["steps"] for r in rows)
    seconds = sum(r["physics"] for r in rows if r["steps"])
    return steps / seconds if seconds > 0 else 0.0


if __name__ == "__main__":
    main()
