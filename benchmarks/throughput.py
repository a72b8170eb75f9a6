"""Where every second of a verified episode goes, beside the floor: raw physics and bare rendering.

Runs the default pipeline (``GenerateConfig()``: context-aware placement with 4 distractors, scene
check, image critic, two 128x128 cameras front and panda/wrist) on long-horizon goals in this
process, one worker on one core (``LP_NUM_THREADS=1``), and prints per goal and overall:

- seconds per accepted episode by phase, as the pipeline measures them (``Funnel.timing``):
  planning, placement, compose (compiling the scene), scene check (settling, stability), physics
  (the robot's control steps), critic views (rendering them) and judging, video render, features,
  video encoding, dataset writing; "other" is the rest of the wall time (inverse kinematics and
  motion plans, recording, oracle checks, logs). Rejected attempts count: their time is part of
  what an accepted episode costs;
- verified episodes per core-hour (accepted episodes the oracle confirms, per hour of the one core);
- the peak resident memory of the process (``resource.getrusage``), i.e. of the one worker, after
  each goal's generation (cumulative: the goals run one after another in the process);
- CPU seconds (``getrusage``) beside wall seconds: on a shared machine the wall time includes
  waiting for a core, the CPU time does not;
- the floor, measured in the same run on the accepted episodes: raw ``mj_step`` replaying each
  episode's recorded actions from its first stored state (one call per physics step, as
  ``benchmarks/stepping.py``), and a bare render of its stored states (``Renderer.rgb_states``,
  the dataset's cameras and size); and the ratio of the pipeline's time to that floor.

    LP_NUM_THREADS=1 .venv/bin/python benchmarks/throughput.py --episodes 3

The datasets are kept under ``--out`` (one per goal, auditable with ``vcage audit``).
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

os.environ.setdefault("LP_NUM_THREADS", "1")  # one rasteriser thread: the worker is one core

import numpy as np  # noqa: E402

import results  # noqa: E402
from vcage.data import DatasetReader  # noqa: E402
from vcage.pipeline.config import GenerateConfig  # noqa: E402
from vcage.pipeline.episode import PHASES, Timing  # noqa: E402
from vcage.pipeline.generate import generate  # noqa: E402
from vcage.planning.goals import GOALS  # noqa: E402
from vcage.scene.compose import compose  # noqa: E402
from vcage.scene.spec import SceneSpec  # noqa: E402
from vcage.sim.render import Renderer  # noqa: E402

DEFAULT_GOALS = ("get_ready_for_work", "prepare_breakfast", "tidy_the_desk")
LABELS = {"scene_check": "scene check", "critic_views": "critic views", "critic_judge": "critic judging",
          "video_render": "video render"}


@dataclass
class Row:
    """One goal's run: the pipeline's timing and counts, and the floor of its accepted episodes."""

    goal: str
    timing: Timing = field(default_factory=Timing)
    wall: float = 0.0
    attempts: int = 0
    accepted: int = 0
    verified: int = 0
    frames: int = 0
    physics_steps: int = 0
    floor_physics: float = 0.0
    floor_render: float = 0.0
    replay_error: float = 0.0  # max |qpos| difference of the replay's last state from the stored one
    cpu: float = 0.0  # CPU seconds of the process while generating (getrusage: robust to a busy machine)
    floor_cpu: float = 0.0  # CPU seconds of the floor's stepping and rendering
    rss_mb: float = 0.0  # peak resident memory of the process after generating, MiB

    def add(self, other: Row) -> None:
        self.timing.add(other.timing)
        for name in ("wall", "attempts", "accepted", "verified", "frames", "physics_steps",
                     "floor_physics", "floor_render", "cpu", "floor_cpu"):
            setattr(self, name, getattr(self, name) + getattr(other, name))
        self.replay_error = max(self.replay_error, other.replay_error)
        self.rss_mb = max(self.rss_mb, other.rss_mb)

    @property
    def other(self) -> float:
        return max(0.0, self.wall - sum(self.timing.phases().values()))

    @property
    def floor(self) -> float:
        return self.floor_physics + self.floor_render


def _floor(row: Row, out: Path, cfg: GenerateConfig) -> None:
    """Raw stepping and bare rendering of the accepted episodes stored at ``out``."""
    import mujoco  # here, after vcage chose the offscreen GL platform (it must be first)

    reader = DatasetReader(out)
    for index in range(reader.num_episodes):
        episode = reader.episode(index)
        states = episode.arrays["states"]
        actions = episode.frames["action"]
        world = compose(SceneSpec.from_dict(episode.extras["scene"]), cfg.sim).make_world(cfg.sim)
        model, data = world.model, world.data
        ctrls = [world.robot.ctrl(a[:7], float(a[7])) for a in actions]
        world.set_state(states[0])
        substeps = world.substeps
        t0, c0 = time.perf_counter(), time.process_time()
        for ctrl in ctrls:
            data.ctrl[:] = ctrl
            for _ in range(substeps):
                mujoco.mj_step(model, data)
        row.floor_physics += time.perf_counter() - t0
        row.floor_cpu += time.process_time() - c0
        row.physics_steps += len(ctrls) * substeps
        row.frames += len(states)
        replayed = data.qpos.copy()
        world.set_state(states[-1])  # the stored state one control step before the replay's end
        world.step(ctrls[-1])
        row.replay_error = max(row.replay_error, float(np.max(np.abs(replayed - data.qpos))))
        with Renderer(world, *cfg.render.size, cfg.render.mesh_detail) as renderer:
            t0, c0 = time.perf_counter(), time.process_time()
            renderer.rgb_states(states, cfg.render.cameras)
            row.floor_render += time.perf_counter() - t0
            row.floor_cpu += time.process_time() - c0


def _run(goal: str, episodes: int, seed: int, root: Path, noslip: int | None) -> Row:
    phrase = next(g for g in GOALS if g.name == goal).phrasings[0]
    out = root / goal
    shutil.rmtree(out, ignore_errors=True)
    cfg = GenerateConfig(seed=seed)
    if noslip is not None:  # e.g. 3, the default before benchmarks/physics_settings.py
        cfg = replace(cfg, sim=replace(cfg.sim, noslip_iterations=noslip))
    t0, c0 = time.perf_counter(), time.process_time()
    funnel = generate(phrase, episodes, out, cfg)
    row = Row(goal, funnel.timing, time.perf_counter() - t0, funnel.attempts, funnel.accepted,
              funnel.accepted - funnel.accepted_oracle_failed, cpu=time.process_time() - c0,
              rss_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)  # KiB on Linux
    _floor(row, out, cfg)
    return row


def _print(rows: list[Row], peak_mb: float) -> None:
    both = [*rows, _total(rows)]
    names = [r.goal[:18] for r in rows] + ["all"]
    print("seconds per accepted episode (share of the wall time)")
    print(f"{'phase':28s}" + "".join(f"{n:>25s}" for n in names))

    def line(label: str, values: list[tuple[float, float]]) -> None:
        print(f"{label:28s}" + "".join(f"{v:14.2f} ({share:5.1%})  " for v, share in values))

    for name in PHASES:
        line(LABELS.get(name, name),
             [(getattr(r.timing, name) / max(r.accepted, 1), getattr(r.timing, name) / r.wall) for r in both])
    line("other", [(r.other / max(r.accepted, 1), r.other / r.wall) for r in both])
    line("wall", [(r.wall / max(r.accepted, 1), 1.0) for r in both])

    def plain(label: str, fmt: str, values: list[float]) -> None:
        print(f"{label:28s}" + "".join(f"{format(v, fmt):>25s}" for v in values))

    print(f"\n{'':28s}" + "".join(f"{n:>25s}" for n in names))
    print(f"{'attempts / accepted':28s}" + "".join(f"{f'{r.attempts} / {r.accepted}':>25s}" for r in both))
    plain("verified per core-hour", ".0f", [r.verified / (r.wall / 3600) for r in both])
    plain("  (per CPU-hour, getrusage)", ".0f", [r.verified / (r.cpu / 3600) for r in both])
    plain("CPU s / wall s", ".2f", [r.cpu / r.wall for r in both])
    plain("frames per episode", ".0f", [r.frames / max(r.accepted, 1) for r in both])
    plain("floor: raw mj_step s/ep", ".2f", [r.floor_physics / max(r.accepted, 1) for r in both])
    plain("  (physics steps/s)", ",.0f", [r.physics_steps / r.floor_physics for r in both])
    plain("floor: bare render s/ep", ".2f", [r.floor_render / max(r.accepted, 1) for r in both])
    plain("  (ms per frame, 2 cameras)", ".2f", [1000 * r.floor_render / max(r.frames, 1) for r in both])
    plain("floor s/ep", ".2f", [r.floor / max(r.accepted, 1) for r in both])
    plain("pipeline wall / floor", ".2f", [r.wall / r.floor for r in both])
    plain("pipeline CPU / floor CPU", ".2f", [r.cpu / r.floor_cpu for r in both])
    plain("physics / raw mj_step", ".2f", [r.timing.physics / r.floor_physics for r in both])
    plain("render / bare render", ".2f", [r.timing.render / r.floor_render for r in both])
    plain("replay max |dqpos|", ".1e", [r.replay_error for r in both])
    plain("peak RSS after goal, MiB", ".0f", [r.rss_mb for r in both])
    print(f"\npeak RSS of the process (goals one after another, then the floor): {peak_mb:.0f} MiB")


def _total(rows: list[Row]) -> Row:
    total = Row("all")
    for row in rows:
        total.add(row)
    return total


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--episodes", type=int, default=3, help="accepted episodes per goal")
    parser.add_argument("--goals", nargs="*", default=list(DEFAULT_GOALS))
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, default=Path("/tmp/vcage-throughput"))
    parser.add_argument("--noslip-iterations", type=int, default=None,
                        help="override SimConfig.noslip_iterations (3 was the default before)")
    parser.add_argument("--record", action="store_true", help="write the overall figures to "
                        "docs/results/throughput.json (the results page)")
    args = parser.parse_args()
    rows = []
    for goal in args.goals:
        rows.append(_run(goal, args.episodes, args.seed, args.out, args.noslip_iterations))
        print(f"{goal}: {rows[-1].accepted} accepted in {rows[-1].attempts} attempts, "
              f"{rows[-1].wall:.0f} s", flush=True)
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # KiB on Linux
    load = os.getloadavg()
    what = "" if args.noslip_iterations is None else f" with noslip_iterations={args.noslip_iterations}"
    print(f"\ndefault pipeline (GenerateConfig(){what}), {args.episodes} episodes per goal, "
          f"seed {args.seed}, "
          f"one worker, LP_NUM_THREADS={os.environ['LP_NUM_THREADS']}, {os.cpu_count()} cores, "
          f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}\n")
    _print(rows, peak_mb)
    if args.record and args.noslip_iterations is None:
        total = _total(rows)
        path = results.record(
            "throughput", "Throughput of verified episodes",
            "How many verified episodes (accepted, and confirmed by the oracle) does the default pipeline "
            "make per hour of one core, and how far is it from the floor of raw physics and bare rendering?",
            {"verified episodes per core-hour (wall)": f"{total.verified / (total.wall / 3600):.0f}",
             "verified episodes per CPU-hour (getrusage)": f"{total.verified / (total.cpu / 3600):.0f}",
             "wall seconds per accepted episode": f"{total.wall / max(total.accepted, 1):.2f}",
             "pipeline wall / floor (raw mj_step + bare render)": f"{total.wall / total.floor:.2f}",
             "peak RSS of the worker": f"{peak_mb:.0f} MiB"},
            f"{total.accepted} accepted episodes ({total.verified} confirmed by the oracle) of "
            f"{total.attempts} attempts, goals {', '.join(args.goals)}, seed {args.seed}; one worker on one "
            f"core, two 128x128 cameras; load average {load[0]:.2f} at the end")
        print(f"recorded in {path}")


if __name__ == "__main__":
    main()
