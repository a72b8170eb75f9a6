"""Long-horizon generation from the subtask database: verify every candidate subtask of a scene,
compose chains of verified subtasks, generate episodes of each chain, audit them against the oracle.

    .venv/bin/python benchmarks/subtask_chains.py --trials 5 --lengths 3 4 --chains 4 --episodes 10

The scene (``--scene``: a scene_spec.json; default a desk written under ``--out``: mouse and mouse
pad, cup and coaster, a red block, a plate, a bell) gets its candidates verified with ``--trials``
trials and the image critic (skipped when ``--out``'s database already holds the scene). For each
length, chains are drawn with seeds 0..``--chains``-1 (``vcage subtasks chain``); each chain
generates ``--episodes`` verified episodes (V-CAGE preset: context-aware placement with 4
distractors, image critic), the dataset is audited, and one row per chain is printed: attempts,
accepted, rejections by stage, label noise (accepted episodes the oracle says fail) and the critic's
agreement with the oracle on the subtasks it judged. Datasets are kept and resumed under ``--out``.
"""

from __future__ import annotations

import argparse
import json
import time
from collections import Counter
from dataclasses import replace
from pathlib import Path

import vcage  # noqa: F401  (sets the GL backend before MuJoCo renders)
from vcage.pipeline.audit import audit
from vcage.pipeline.config import ExecutorConfig, GenerateConfig
from vcage.pipeline.generate import generate
from vcage.scene.spec import ObjectSpec, SceneSpec
from vcage.subtasks.candidates import candidates
from vcage.subtasks.chains import compose
from vcage.subtasks.scenes import resolve
from vcage.subtasks.store import SubtaskStore
from vcage.subtasks.trial import TrialConfig
from vcage.subtasks.verify import Funnel, verify_all

DESK = SceneSpec(objects=(
    ObjectSpec("mouse", "mouse", (0.47, -0.24)), ObjectSpec("pad", "mouse_pad", (0.64, -0.22)),
    ObjectSpec("cup", "cup", (0.46, -0.04)), ObjectSpec("coaster", "coaster", (0.62, -0.02)),
    ObjectSpec("block", "block", (0.47, 0.14), color="red"), ObjectSpec("plate", "plate", (0.64, 0.2)),
    ObjectSpec("bell", "bell", (0.5, 0.27))))


def verified_db(scene_path: Path, db: Path, trials: int) -> tuple[str, Funnel | None]:
    """The database holding ``scene_path``'s verified candidates (verified now unless it already does)."""
    from vcage.critics.base import CriticConfig, make_critic

    record, spec = resolve(str(scene_path))
    with SubtaskStore(db) as store:
        if store.subtasks(scene_id=record.id):
            return record.id, None
        critic = make_critic(CriticConfig(name="image"))
        funnel = verify_all(record, spec, candidates(record.id, spec), store, critic,
                            TrialConfig(trials=trials), "image")
    return record.id, funnel


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene", type=Path, default=None, help="a scene_spec.json (default: the desk)")
    parser.add_argument("--trials", type=int, default=5, help="verification trials per candidate")
    parser.add_argument("--lengths", type=int, nargs="+", default=[3, 4])
    parser.add_argument("--chains", type=int, default=4, help="chains drawn per length (seeds 0..N-1)")
    parser.add_argument("--episodes", type=int, default=10, help="accepted episodes per chain")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--out", type=Path, default=Path("out/bench_chains"))
    args = parser.parse_args()

    t0 = time.perf_counter()
    args.out.mkdir(parents=True, exist_ok=True)
    scene = args.scene
    if scene is None:
        scene = args.out / "desk" / "scene_spec.json"
        scene.parent.mkdir(parents=True, exist_ok=True)
        scene.write_text(json.dumps(DESK.to_dict()))
    db = args.out / "subtasks.db"
    scene_id, funnel = verified_db(scene, db, args.trials)
    with SubtaskStore(db, readonly=True) as store:
        rows = store.subtasks(scene_id=scene_id)
    accepted = sum(r.status == "accepted" for r in rows)
    source = "verified now" if funnel else "from the database"
    print(f"scene {scene_id}: {len(rows)} candidates, {accepted} accepted ({source}, "
          f"{rows[0].trials if rows else 0} trials each)")

    header = (f"{'chain':10} {'steps':>5} {'acc':>4} {'att':>4} {'rejected by stage':28} {'noise':>6} "
              f"{'judged':>6} {'agree':>6}  subtasks")
    print(header)
    totals: Counter[str] = Counter()
    seen: set[tuple[str, ...]] = set()
    for length in args.lengths:
        for seed in range(args.chains):
            with SubtaskStore(db, readonly=True) as store:
                chain = compose(store, length, seed, scene_id)
            seen.add(chain.provenance.subtasks)
            cfg = replace(GenerateConfig(seed=seed), synthesized=chain.scene, chain=chain.provenance,
                          executor=ExecutorConfig(workers=args.workers))
            cfg = replace(cfg, render=replace(cfg.render, size=(args.size, args.size)))
            root = args.out / f"len{length}-seed{seed}"
            generate(chain.plan.instruction, args.episodes, root, cfg, plan=chain.plan, total=True)
            report = audit(root)
            lines = (root / "meta" / "vcage_attempts.jsonl").read_text().splitlines()
            stages = Counter(json.loads(line)["stage"] for line in lines if line.strip())
            rejected = ", ".join(f"{k} {v}" for k, v in sorted(stages.items()) if k != "accepted") or "-"
            agreed = f"{report.agreement:.1%}" if report.judged_subtasks else "n/a"
            print(f"len{length}-s{seed:<4} {length:>5} {report.accepted:>4} {report.attempts:>4} "
                  f"{rejected:28} {report.label_noise:>6.1%} {report.judged_subtasks:>6} {agreed:>6}  "
                  f"{'; '.join(r.description for r in chain.records)}", flush=True)
            totals.update(accepted=report.accepted, attempts=report.attempts,
                          noisy=report.accepted_oracle_failed, judged=report.judged_subtasks,
                          agree=report.true_accept + report.true_reject)
    noise = totals["noisy"] / totals["accepted"] if totals["accepted"] else 0.0
    agree = totals["agree"] / totals["judged"] if totals["judged"] else 0.0
    print(f"\nall chains: {len(seen)} distinct of {args.chains * len(args.lengths)} drawn; "
          f"{totals['accepted']} accepted episodes in {totals['attempts']} attempts; label noise {noise:.1%} "
          f"({totals['noisy']} of {totals['accepted']}); critic agreement {agree:.1%} on {totals['judged']} "
          f"judged subtasks; {time.perf_counter() - t0:.0f} s wall")


if __name__ == "__main__":
    main()
