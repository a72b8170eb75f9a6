"""Scene instantiation per placement method and density: success, interpenetration, stability, time.

For each method (context-aware, naive, rejection) and each object count, every seed draws the same
objects from the whole catalog onto the standard table, places them, composes the scene and checks
it in physics (contacts deeper than 1 mm at t=0; settling 1 s: moved > 1 cm or 0.1 rad, or fell).
A scene succeeds when every object was placed and the check found nothing. Scenes with an object
outside the arm's top-down reach are counted separately. One example scene per
method and density is rendered from the top camera to PNG (and all of them into one sheet).

    .venv/bin/python benchmarks/placement.py --seeds 200 --workers 2
"""

from __future__ import annotations

import argparse
import re
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from vcage.errors import PlacementError, SimulationError
from vcage.scene.compose import compose
from vcage.scene.layout import Distractors, LayoutSpec
from vcage.scene.placement import PLACERS, place
from vcage.scene.stability import StabilityReport, check_stability
from vcage.skills.reachability import reach_map

METHODS = ("context", "rejection", "naive")
TILE = (480, 360)
CATALOG_WIDE = 0.3  # the largest footprint side in the catalog: every type may be drawn


def _one(job: tuple[str, int, int, bool]) -> dict:
    method, count, seed, _ = job
    layout = LayoutSpec(distractors=Distractors(count, max_size=CATALOG_WIDE))
    row = {"method": method, "count": count, "seed": seed, "placed": False, "interpenetrating": False,
           "unstable": False, "unreachable": False, "seconds": [], "coverage": 0.0, "reason": ""}
    try:
        result = place(layout, np.random.default_rng(seed), method, reach=reach_map())
    except PlacementError as exc:
        row["reason"] = str(exc).split(":")[0]
        return row
    r_in, r_out = reach_map().interval(result.scene.table.height)
    far = [o.name for o in result.scene.objects
           if not r_in <= float(np.hypot(*o.xy)) <= r_out]  # the robot's base axis is at x = y = 0
    row.update(placed=True, seconds=result.stats.seconds, coverage=result.stats.coverage,
               unreachable=bool(far))
    try:
        report = check_stability(compose(result.scene).make_world())
    except SimulationError as exc:  # the physics could not even start from this state
        report = StabilityReport(error=str(exc))
    row.update(interpenetrating=report.interpenetrating, unstable=not report.stable,
               reason="" if report.ok else report.reason())
    return row


def _render(method: str, count: int, seed: int, out: Path) -> Path | None:
    from PIL import Image

    from vcage.sim.render import Renderer

    layout = LayoutSpec(distractors=Distractors(count, max_size=CATALOG_WIDE))
    try:
        scene = place(layout, np.random.default_rng(seed), method, reach=reach_map()).scene
    except PlacementError:
        return None
    world = compose(scene).make_world()
    world.settle(1.0)
    with Renderer(world, *TILE) as r:  # 4:3 frames the whole table top
        img = r.rgb("top")
    path = out / f"{method}_{count:02d}.png"
    Image.fromarray(img).save(path)
    return path


def _sheet(paths: dict[tuple[str, int], Path | None], counts: list[int], out: Path) -> Path:
    from PIL import Image, ImageDraw

    w, h = TILE
    sheet = Image.new("RGB", (w * len(counts), (h + 24) * len(METHODS)), "white")
    draw = ImageDraw.Draw(sheet)
    for i, method in enumerate(METHODS):
        for j, count in enumerate(counts):
            y = i * (h + 24)
            draw.text((j * w + 6, y + 6), f"{method}, {count} objects", fill="black")
            path = paths.get((method, count))
            if path is not None:
                sheet.paste(Image.open(path), (j * w, y + 24))
            else:
                draw.text((j * w + 6, y + 40), "placement failed", fill="red")
    path = out / "sheet.png"
    sheet.save(path)
    return path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=200)
    parser.add_argument("--counts", type=int, nargs="*", default=[5, 10, 20, 30])
    parser.add_argument("--methods", nargs="*", default=list(METHODS), choices=PLACERS.names())
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", type=Path, default=Path("out/benchmarks/placement"))
    args = parser.parse_args()
    reach_map()  # computed (or loaded) once before the workers start
    jobs = [(m, c, s, False) for m in args.methods for c in args.counts for s in range(args.seeds)]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as pool:
        rows = list(pool.map(_one, jobs, chunksize=8))
    wall = time.perf_counter() - t0
    print(f"scene instantiation on the standard table (0.8 x 1.2 m), objects drawn from the whole "
          f"catalog; {args.seeds} seeds per cell, {len(jobs)} scenes, {wall:.0f} s wall on "
          f"{args.workers} workers\n")
    head = (f"{'method':10s} {'objects':>7s} {'success':>8s} {'placed':>7s} {'interpen.':>9s} "
            f"{'unstable':>8s} {'unreach.':>8s} {'ms/obj p50':>10s} {'ms/obj p95':>10s} {'coverage':>8s}")
    print(head)
    reasons: dict[tuple[str, int], dict[str, int]] = {}
    for method in args.methods:
        for count in args.counts:
            cell = [r for r in rows if r["method"] == method and r["count"] == count]
            n = len(cell)
            placed = [r for r in cell if r["placed"]]
            ok = sum(r["placed"] and not r["interpenetrating"] and not r["unstable"] for r in cell)
            secs = np.concatenate([r["seconds"] for r in placed]) if placed else np.zeros(1)
            cov = np.mean([r["coverage"] for r in placed]) if placed else 0.0
            print(f"{method:10s} {count:7d} {ok / n:8.1%} {len(placed) / n:7.1%} "
                  f"{sum(r['interpenetrating'] for r in cell) / n:9.1%} "
                  f"{sum(r['unstable'] for r in cell) / n:8.1%} "
                  f"{sum(r['unreachable'] for r in cell) / n:8.1%} {np.median(secs) * 1e3:10.3f} "
                  f"{np.percentile(secs, 95) * 1e3:10.3f} {cov:8.1%}")
            for r in cell:
                if r["reason"]:
                    first = re.sub(r"'[^']*'", "X", r["reason"].split(";")[0].split("(")[0])
                    key = re.sub(r"\d+", "N", first).strip()[:60]
                    reasons.setdefault((method, count), {}).setdefault(key, 0)
                    reasons[(method, count)][key] += 1
    print("\nplaced: every object placed; success: placed, no interpenetration and stable; "
          "interpen. / unstable / unreach. (an object outside the arm's top-down reach): shares of "
          "all scenes")
    if reasons:
        print("\nfirst failure reason per scene (grouped):")
        for (method, count), counts in reasons.items():
            top = sorted(counts.items(), key=lambda kv: -kv[1])[:3]
            print(f"  {method} {count}: " + "; ".join(f"{k} x{v}" for k, v in top))
    args.out.mkdir(parents=True, exist_ok=True)
    paths = {(m, c): _render(m, c, 0, args.out) for m in args.methods for c in args.counts}
    print(f"\nexample scenes (seed 0, top camera): {_sheet(paths, args.counts, args.out)}")


if __name__ == "__main__":
    main()
