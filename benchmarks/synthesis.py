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
from vcage.scene.spec import ObjectSpec, SceneSpec
from vcage.synthesis.compositor import Compositor
from vcage.synthesis.description import parse_description
from vcage.synthesis.driver import SynthesisConfig, synthesize
from vcage.synthesis.matching import match
from vcage.synthesis.perturb import PRESETS
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
    args = parser.parse_args()
    if not args.skip_matching:
        matching_sweep(args.seeds)
    end_to_end(1.0, args.scene_seeds)
    if args.lambdas:
        lambda_ablation([float(v) for v in args.lambdas.split(",")], args.scene_seeds)


if __name__ == "__main__":
    main()
