"""V-CAGE versus Vanilla on long-horizon goals, on the same seeds.

For each goal both modes generate N accepted episodes into a fresh dataset (two 128x128 cameras,
offline planner; V-CAGE: context-aware placement, scene check, image critic; Vanilla: naive
placement, no check, no critic). Printed per goal and overall: label noise of the accepted
episodes (share the oracle says failed), rejection rate (rejected attempts / attempts), the image
critic's agreement with the oracle on the subtasks it judged (precision, recall), verified
episodes per core-hour (accepted episodes the oracle confirms, per hour of one core), and the
ratio of total time to physics plus rendering. And how many accepted episodes started with the
plan's objects fused into another object (naive placement leaves them so; V-CAGE's scene check
refuses such scenes), with the label noise of the others apart: how much of Vanilla's noise
remains in physically valid scenes.

    LP_NUM_THREADS=1 .venv/bin/python benchmarks/vcage_vs_vanilla.py --episodes 50 --workers 2

The datasets are kept under ``--out`` (one per goal and mode, auditable with ``vcage audit``), and
each finished job's row is appended to ``--out/results.jsonl``; a rerun with the same arguments
skips the jobs already there, so a long run can be stopped and resumed.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

os.environ.setdefault("LP_NUM_THREADS", "1")  # one rasteriser thread: a worker is one core

import results  # noqa: E402
from vcage.pipeline.audit import audit  # noqa: E402
from vcage.pipeline.config import GenerateConfig  # noqa: E402
from vcage.pipeline.generate import generate  # noqa: E402
from vcage.planning.goals import GOALS  # noqa: E402
from vcage.scene.stability import StabilityConfig  # noqa: E402

DEFAULT_GOALS = ("get_ready_for_work", "prepare_breakfast", "tidy_the_desk", "set_the_table",
                 "build_a_tower", "sort_blocks_by_colour")


def _run(job: tuple[str, str, int, int, str]) -> dict:
    goal, mode, episodes, seed, root = job
    phrase = next(g for g in GOALS if g.name == goal).phrasings[0]
    out = Path(root) / f"{goal}-{mode}"
    shutil.rmtree(out, ignore_errors=True)
    t0 = time.perf_counter()
    cfg = GenerateConfig(seed=seed) if mode == "vcage" else GenerateConfig.vanilla(seed=seed)
    funnel = generate(phrase, episodes, out, cfg)
    wall = time.perf_counter() - t0
    report = audit(out)
    stats = funnel.to_dict()
    return {"goal": goal, "mode": mode, "episodes": episodes, "seed": seed,
            "attempts": funnel.attempts, "accepted": funnel.accepted,
            "noisy": funnel.accepted_oracle_failed, "judged": report.judged_subtasks,
            "fused": report.accepted_fused, "fused_noisy": report.accepted_fused_oracle_failed,
            "tp": report.true_accept, "fp": report.false_accept, "fn": report.false_reject,
            "tn": report.true_reject, "wall": wall, "physics": funnel.timing.physics,
            "render": funnel.timing.render, "stages": stats["stages"]}


def _line(name: str, rows: list[dict]) -> str:
    att = sum(r["attempts"] for r in rows)
    acc = sum(r["accepted"] for r in rows)
    noisy = sum(r["noisy"] for r in rows)
    tp, fp, fn = (sum(r[k] for r in rows) for k in ("tp", "fp", "fn"))
    judged = sum(r["judged"] for r in rows)
    hours = sum(r["wall"] for r in rows) / 3600
    verified = acc - noisy
    ratio = sum(r["wall"] for r in rows) / max(1e-9, sum(r["physics"] + r["render"] for r in rows))
    crit = (f"{(tp + sum(r['tn'] for r in rows)) / judged:6.1%} {tp / max(1, tp + fp):6.1%} "
            f"{tp / max(1, tp + fn):6.1%}" if judged else f"{'-':>6s} {'-':>6s} {'-':>6s}")
    # rows of runs before the fused starts were recorded lack them: counted as clear
    fused, fused_noisy = (sum(r.get(k, 0) for r in rows) for k in ("fused", "fused_noisy"))
    clear = f"{(noisy - fused_noisy) / (acc - fused):7.1%}" if acc > fused else f"{'n/a':>7s}"
    return (f"{name:24s} {acc:4d} {noisy / max(1, acc):7.1%} {(att - acc) / max(1, att):7.1%} {crit} "
            f"{verified / hours if hours else 0:9.1f} {ratio:6.2f} {fused:5d} {clear}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--episodes", type=int, default=50)
    parser.add_argument("--goals", nargs="*", default=list(DEFAULT_GOALS))
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default="out/benchmarks/vcage_vs_vanilla",
                        help="where the datasets and results.jsonl go")
    parser.add_argument("--record", action="store_true", help="write the overall figures to "
                        "docs/results/vcage_vs_vanilla.json (the results page)")
    args = parser.parse_args()
    root = Path(args.out)
    root.mkdir(parents=True, exist_ok=True)
    ledger = root / "results.jsonl"
    done = [json.loads(line) for line in ledger.read_text().splitlines()] if ledger.exists() else []
    done = [r for r in done if r["episodes"] == args.episodes and r["seed"] == args.seed]
    have = {(r["goal"], r["mode"]) for r in done}
    jobs = [(g, m, args.episodes, args.seed, str(root)) for g in args.goals
            for m in ("vcage", "vanilla") if (g, m) not in have]
    rows = [r for r in done if r["goal"] in args.goals]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as pool:
        for future in as_completed([pool.submit(_run, job) for job in jobs]):
            row = future.result()
            rows.append(row)
            with ledger.open("a") as f:
                f.write(json.dumps(row) + "\n")
            print(f"done {row['goal']} / {row['mode']}: {row['accepted']} accepted of "
                  f"{row['attempts']} attempts in {row['wall']:.0f} s", flush=True)
    wall = time.perf_counter() - t0
    print(f"{args.episodes} accepted episodes per goal and mode, same seeds, two 128x128 cameras; "
          f"{wall:.0f} s wall for {len(jobs)} new jobs on {args.workers} workers (one core each)\n")
    print(f"{'goal / mode':24s} {'acc':>4s} {'noise':>7s} {'reject':>7s} {'agree':>6s} {'prec':>6s} "
          f"{'recall':>6s} {'verif/c-h':>9s} {'t/(p+r)':>6s} {'fused':>5s} {'n|clear':>7s}")
    for goal in args.goals:
        for mode in ("vcage", "vanilla"):
            print(_line(f"{goal} / {mode}", [r for r in rows if r["goal"] == goal and r["mode"] == mode]))
    print()
    for mode in ("vcage", "vanilla"):
        print(_line(f"overall / {mode}", [r for r in rows if r["mode"] == mode]))
    print("\nnoise: accepted episodes the oracle says failed; reject: rejected attempts / attempts; "
          "agree/prec/recall: image critic vs oracle on judged subtasks (accept = positive); "
          "verif/c-h: oracle-confirmed accepted episodes per core-hour; t/(p+r): total time over "
          "physics plus rendering; fused: accepted episodes that started with the plan's objects fused "
          f"into another object (deeper than {1000 * StabilityConfig().penetration:.0f} mm); n|clear: label "
          "noise of the other accepted episodes")
    stages: dict[str, dict[str, int]] = {}
    for r in rows:
        for stage, n in r["stages"].items():
            stages.setdefault(r["mode"], {}).setdefault(stage, 0)
            stages[r["mode"]][stage] += n
    for mode, counts in stages.items():
        print(f"attempt outcomes ({mode}): " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    if args.record:
        print(f"recorded in {_record(args, rows)}")


def _record(args: argparse.Namespace, rows: list[dict]) -> Path:
    figures: dict[str, str] = {}
    for mode, label in (("vcage", "V-CAGE"), ("vanilla", "Vanilla")):
        mine = [r for r in rows if r["mode"] == mode]
        acc, noisy = sum(r["accepted"] for r in mine), sum(r["noisy"] for r in mine)
        fused, fused_noisy = (sum(r.get(k, 0) for r in mine) for k in ("fused", "fused_noisy"))
        figures[f"label noise, {label}"] = f"{noisy} of {acc} ({noisy / max(1, acc):.1%})"
        if fused:
            clear = acc - fused
            figures[f"label noise, {label}, clear starts only"] = \
                f"{noisy - fused_noisy} of {clear} ({(noisy - fused_noisy) / max(1, clear):.1%})"
        hours = sum(r["wall"] for r in mine) / 3600
        figures[f"oracle-confirmed episodes per core-hour, {label}"] = f"{(acc - noisy) / hours:.0f}"
        judged = sum(r["judged"] for r in mine)
        if judged:
            agree = sum(r["tp"] + r["tn"] for r in mine)
            figures[f"critic agreement with the oracle, {label}"] = \
                f"{agree / judged:.1%} of {judged} subtasks"
    return results.record(
        "vcage_vs_vanilla", "Label noise: V-CAGE against Vanilla",
        "What share of the accepted episodes fail the oracle's audit, with context-aware placement and the "
        "image critic (V-CAGE) and without them (Vanilla), on the same seeds?",
        figures, f"{args.episodes} accepted episodes per goal and mode, seed {args.seed}, goals "
        f"{', '.join(args.goals)}; {args.workers} workers, two 128x128 cameras")


if __name__ == "__main__":
    main()
