"""Scene synthesis offline: template matching on compositor goal images across the perturbation sweep,
and end to end (prompt to settled scene) on 10 prompts: valid scenes per minute and the funnel.

Matching: a fixed four-object scene (mouse, book, two blocks), one goal image per perturbation preset
and seed; detection rate, median and p95 position error (mm) and median yaw error of the asymmetric
objects (deg; the "turn" preset turns every object by up to 60 degrees beyond the layout, the others
barely turn them); dropped objects flagged lost. End to end: ``vcage.synthesis.driver.synthesize`` with the
offline compositor, no reach limit, 3 attempts; per prompt: valid or the refusing stage, attempts,
seconds, and the relations of ``D_scene`` that hold after settling. ``--lambdas 0.1,1,10`` adds an
ablation of the refine step's semantic weight. Run from the repository root:
``.venv/bin/python benchmarks/synthesis.py [--seeds N] [--scene-seeds K] [--lambdas L,...]``.
"""

from __future__ import annotations

import argparse
import math
import time
from collections import Counter

import numpy as np

import vcage  # noqa: F401  (sets the GL backend before MuJoCo renders)
from vcage.errors import VcageError
from vcage.scene.compose import compose
from vcage.scene.spec import ObjectSpec, SceneSpec, TableSpec
from vcage.synthesis.compositor import Compositor
from vcage.synthesis.costs import Problem, Weights
from vcage.synthesis.description import SceneDescription, parse_description
from vcage.synthesis.driver import SynthesisConfig, synthesize
from vcage.synthesis.errors import RefineRejected
from vcage.synthesis.footprints import penetration
from vcage.synthesis.matching import match
from vcage.synthesis.perturb import PRESETS
from vcage.synthesis.refine import RefineConfig, refine
from vcage.synthesis.views import render_top

PROMPTS = ["organize the breakfast table", "tidy the desk", "serve tea", "set the table", "display the fruit",
           "put the apple in the bowl and the cup left of the plate", "put the bread in the basket",
           "a mug next to a plate", "some fruit", "do the paperwork"]
OBJECTS = (ObjectSpec("mouse", "mouse", (0.45, 0.3), 0.4), ObjectSpec("book", "book", (0.7, -0.3), -0.3),
           ObjectSpec("red", "block", (0.33, -0.25), 0.2, color="red"),
           ObjectSpec("blue", "block", (0.6, 0.1), 0.9, color="blue"))
DESC = parse_description({
    "prompt": "bench", "text": "a row", "objects": [{"name": o.name, "type": o.type, "color": o.color}
                                                    for o in OBJECTS],
    "relations": [{"kind": "left_of", "a": "mouse", "b": "blue"},
                  {"kind": "aligned", "a": "blue", "b": "book"}, {"kind": "near", "a": "red", "b": "book"}]})


def matching_sweep(seeds: int) -> None:
    world = compose(SceneSpec(objects=OBJECTS)).make_world()
    view, empty = render_top(world)
    print("matching on compositor goal images (4 objects; yaw of mouse and book)")
    print(f"{'preset':10s} {'detected':>9s} {'pos med mm':>11s} {'pos p95 mm':>11s} {'yaw med deg':>12s} "
          f"{'yaw p95 deg':>12s} {'drops flagged':>14s} {'s/image':>8s}")
    for preset, pert in PRESETS.items():
        found, pos, yaws, flagged, drops, secs = 0, [], [], 0, 0, []
        for seed in range(seeds):
            edit = Compositor(pert).edit(view, empty, DESC, np.random.default_rng(seed))
            t0 = time.perf_counter()
            rep = match(view, empty, edit.image, {o.name: (o.type, o.color) for o in DESC.objects})
            secs.append(time.perf_counter() - t0)
            assert edit.truth is not None
            for name, (x, y, yaw) in edit.truth.items():
                m = rep.matches[name]
                found += m.found
                if m.found:
                    pos.append(1000 * math.hypot(m.xy[0] - x, m.xy[1] - y))
                    if name in ("mouse", "book"):
                        yaws.append(abs(math.degrees((m.yaw - yaw + math.pi) % (2 * math.pi) - math.pi)))
            drops += len(edit.dropped)
            flagged += sum(1 for d in edit.dropped if d in rep.lost)
        total = sum(len(OBJECTS) - (1 if pert.drop else 0) for _ in range(seeds))
        print(f"{preset:10s} {found / total:9.1%} {np.median(pos):11.2f} {np.percentile(pos, 95):11.2f} "
              f"{np.median(yaws):12.2f} {np.percentile(yaws, 95):12.2f} "
              f"{f'{flagged}/{drops}' if drops else '-':>14s} {np.mean(secs):8.2f}")


def end_to_end(lam: float = 1.0, seeds: int = 1, verbose: bool = True) -> dict[str, float]:
    """Each prompt with seeds 0..seeds-1: valid scenes, relations of D_scene held after settling (in
    valid scenes, the share of scenes with all held and of relations held), mean displacement of the
    refine step from the matched poses, refine seconds; the funnel's rejections by stage."""
    if verbose:
        print(f"\nend to end, offline compositor, 3 attempts, lambda {lam}, seeds 0..{seeds - 1}")
    t_all = time.perf_counter()
    valid, runs, stages = 0, 0, Counter()
    held = total = all_held = 0
    moves, refine_s = [], []
    for prompt in PROMPTS:
        for seed in range(seeds):
            runs += 1
            t0 = time.perf_counter()
            try:
                result = synthesize(prompt, SynthesisConfig(seed=seed, lam=lam))
                funnel = result.funnel
                verdict = "valid"
                valid += 1
                k, n = map(int, funnel[-1]["detail"]["relations_held"].split("/"))
                held, total, all_held = held + k, total + n, all_held + (k == n)
                verdict += f", relations {k}/{n}"
            except VcageError as exc:
                funnel, verdict = [], f"refused: {type(exc).__name__}"
            for f in funnel:
                if f["status"] == "rejected":
                    stages[f["stage"]] += 1
                if f["stage"] == "refine" and f["status"] == "ok":
                    moves.append(f["detail"]["mean_displacement_m"])
                    refine_s.append(f["detail"]["seconds"])
            tries = 1 + max((f["attempt"] or 0) for f in funnel) if funnel else "-"
            if verbose:
                seconds = time.perf_counter() - t0
                print(f"  {prompt[:48]:48s} {verdict:32s} attempts {tries}  {seconds:5.1f} s")
    minutes = (time.perf_counter() - t_all) / 60
    out = {"valid": valid, "runs": runs, "per_minute": valid / minutes,
           "all_held": all_held / max(1, valid), "held": held / max(1, total),
           "displacement_mm": 1000 * float(np.mean(moves)) if moves else math.nan,
           "refine_s": float(np.mean(refine_s)) if refine_s else math.nan}
    if verbose:
        print(f"valid scenes: {valid}/{runs}; {out['per_minute']:.1f} valid scenes per minute; rejections "
              f"by stage in valid runs: {dict(stages)}")
        print(f"relations of D_scene held after settling: all of them in {all_held}/{valid} valid scenes; "
              f"{held}/{total} relations; refine: mean displacement {out['displacement_mm']:.1f} mm, "
              f"{out['refine_s']:.2f} s per scene")
    return out


SCALING_TYPES = ("block", "apple", "cup", "orange", "dice", "mug", "book", "phone", "banana", "can",
                 "bowl", "sponge", "marker")


def scaling_description(n: int) -> SceneDescription:
    """``n`` catalog objects (cycling :data:`SCALING_TYPES`) and ``n - 1`` relations chaining them:
    left_of, near and aligned in turn."""
    objects = [{"name": f"o{i}", "type": SCALING_TYPES[i % len(SCALING_TYPES)]} for i in range(n)]
    kinds = ("left_of", "near", "aligned")
    relations = [{"kind": kinds[i % 3], "a": f"o{i}", "b": f"o{i + 1}"} for i in range(n - 1)]
    return parse_description({"prompt": f"{n} objects", "text": "a chain", "objects": objects,
                              "relations": relations})


def scattered(problem: Problem, rng: np.random.Generator) -> dict[str, tuple[float, float, float]]:
    """Poses of the problem's objects drawn one by one, uniformly on the table, until each is clear
    of those before it (as an initial image shows them: no overlap, relations left to chance)."""
    x0, y0, x1, y1 = problem.table
    ps = np.zeros((len(problem.names), 3))
    for k in range(len(ps)):
        for _ in range(2000):
            ps[k] = (rng.uniform(x0, x1), rng.uniform(y0, y1), rng.uniform(-math.pi, math.pi))
            mine = problem.pairs[(problem.pairs.max(1) == k)]
            if not len(mine) or penetration(ps, problem.half, mine).max() < -problem.margin:
                break
        else:
            raise SystemExit(f"no room for object {k} of {len(ps)}")
    return {n: (float(p[0]), float(p[1]), float(p[2])) for n, p in zip(problem.names, ps, strict=True)}


def refine_scaling(sizes: list[int], seeds: int, lams: list[float]) -> None:
    """The refine step alone on ``n``-object descriptions from starts scattered clear of each other
    that violate the relations: accepted arrangements, seconds per scene (the rejected ones
    included: they run every start), mean displacement from the start, per size and lambda."""
    print(f"\nrefine alone: n objects scattered clear of each other on the table, relations left to chance, "
          f"seeds 0..{seeds - 1}")
    print(f"{'objects':>7s} {'lambda':>7s} {'accepted':>9s} {'s/scene':>8s} {'s max':>6s} "
          f"{'s/accepted':>11s} {'displ mm':>9s}")
    table = TableSpec()
    for n in sizes:
        desc = scaling_description(n)
        for lam in lams:
            ok, secs, moves, ok_secs = 0, [], [], []
            for seed in range(seeds):
                rng = np.random.default_rng(seed)
                problem = Problem.build(desc, table)
                start = scattered(problem, rng)
                cfg = RefineConfig(weights=Weights(lam=lam))
                t0 = time.perf_counter()
                try:
                    result = refine(problem, start, cfg, rng)
                    ok += 1
                    moves.append(result.displacement)
                    ok_secs.append(time.perf_counter() - t0)
                except RefineRejected:
                    pass
                secs.append(time.perf_counter() - t0)
            displ = f"{1000 * np.mean(moves):9.1f}" if moves else f"{'n/a':>9s}"
            per_ok = f"{np.mean(ok_secs):11.2f}" if ok_secs else f"{'n/a':>11s}"
            print(f"{n:7d} {lam:7.2f} {ok:5d}/{seeds:<3d} {np.mean(secs):8.2f} {max(secs):6.2f} {per_ok} "
                  f"{displ}")


def lambda_ablation(lams: list[float], seeds: int) -> None:
    print(f"\nrefine: lambda ablation (the same prompts, seeds 0..{seeds - 1})")
    print(f"{'lambda':>7s} {'valid':>7s} {'all held':>9s} {'rel held':>9s} {'displ mm':>9s} "
          f"{'refine s':>9s} {'scenes/min':>11s}")
    for lam in lams:
        r = end_to_end(lam, seeds, verbose=False)
        print(f"{lam:7.2f} {int(r['valid']):3d}/{int(r['runs']):<3d} {r['all_held']:9.1%} {r['held']:9.1%} "
              f"{r['displacement_mm']:9.1f} {r['refine_s']:9.2f} {r['per_minute']:11.1f}")


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seeds", type=int, default=5, help="goal images per preset in the matching sweep")
    parser.add_argument("--scene-seeds", type=int, default=1, help="seeds per prompt end to end")
    parser.add_argument("--lambdas", type=str, default="", help="comma-separated lambdas to ablate, e.g. "
                        "0.1,1,10 (empty: no ablation)")
    parser.add_argument("--skip-matching", action="store_true")
    parser.add_argument("--refine-seeds", type=int, default=8, help="starts per size in the refine-alone "
                        "measurement")
    parser.add_argument("--sizes", type=str, default="4,7,10,12", help="object counts of the refine-alone "
                        "measurement (empty: skip it)")
    args = parser.parse_args()
    if not args.skip_matching:
        matching_sweep(args.seeds)
    end_to_end(1.0, args.scene_seeds)
    lams = [float(v) for v in args.lambdas.split(",")] if args.lambdas else []
    if lams:
        lambda_ablation(lams, args.scene_seeds)
    if args.sizes:
        refine_scaling([int(v) for v in args.sizes.split(",")], args.refine_seeds, lams or [1.0])


if __name__ == "__main__":
    main()
