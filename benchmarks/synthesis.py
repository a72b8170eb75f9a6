"""Scene synthesis offline: template matching on compositor goal images across the perturbation sweep,
and end to end (prompt to settled scene) on 10 prompts: valid scenes per minute and the funnel.

Matching: a fixed four-object scene (mouse, book, two blocks), one goal image per perturbation preset
and seed; detection rate, median and p95 position error (mm) and median yaw error of the asymmetric
objects (deg); dropped objects flagged lost. End to end: ``vcage.synthesis.driver.synthesize`` with the
offline compositor, no reach limit, 3 attempts; per prompt: valid or the refusing stage, attempts,
seconds. Run from the repository root: ``.venv/bin/python benchmarks/synthesis.py [--seeds N]``.
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
          f"{'drops flagged':>14s} {'s/image':>8s}")
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
              f"{np.median(yaws):12.2f} {f'{flagged}/{drops}' if drops else '-':>14s} {np.mean(secs):8.2f}")


def end_to_end() -> None:
    print("\nend to end, offline compositor, 3 attempts, seed 0")
    t_all = time.perf_counter()
    valid, stages = 0, Counter()
    for prompt in PROMPTS:
        t0 = time.perf_counter()
        try:
            result = synthesize(prompt, SynthesisConfig(seed=0))
            funnel = result.funnel
            verdict = "valid"
            valid += 1
        except VcageError as exc:
            funnel, verdict = [], f"refused: {type(exc).__name__}"
        for f in funnel:
            if f["status"] == "rejected":
                stages[f["stage"]] += 1
        tries = 1 + max((f["attempt"] or 0) for f in funnel) if funnel else "-"
        print(f"  {prompt[:48]:48s} {verdict:32s} attempts {tries}  {time.perf_counter() - t0:5.1f} s")
    minutes = (time.perf_counter() - t_all) / 60
    print(f"valid scenes: {valid}/{len(PROMPTS)}; {valid / minutes:.1f} valid scenes per minute; "
          f"rejections by stage in valid runs: {dict(stages)}")


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seeds", type=int, default=5)
    args = parser.parse_args()
    matching_sweep(args.seeds)
    end_to_end()


if __name__ == "__main__":
    main()
