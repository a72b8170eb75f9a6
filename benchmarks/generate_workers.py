"""Generation throughput with one and with several local worker processes, on the same episodes.

Generates the same episodes (same goal and seed) with ``--workers 1`` (the baseline) and with each
count in ``--workers``, checks the datasets are identical (simulator states of every episode), and
prints wall time, episodes per hour, episodes per core-hour and the speed-up over one worker.

    .venv/bin/python benchmarks/generate_workers.py --episodes 8 --workers 2
"""

from __future__ import annotations

import argparse
import os
import shutil
import tempfile
from dataclasses import replace
from pathlib import Path

os.environ.setdefault("LP_NUM_THREADS", "1")  # one rasteriser thread: a worker is one core

import numpy as np  # noqa: E402

from vcage.data import DatasetReader  # noqa: E402
from vcage.pipeline.config import ExecutorConfig, GenerateConfig  # noqa: E402
from vcage.pipeline.generate import generate  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--episodes", type=int, default=8)
    parser.add_argument("--workers", type=int, nargs="*", default=[2])
    parser.add_argument("--instruction", default="get ready for work")
    args = parser.parse_args()
    root = Path(tempfile.mkdtemp(prefix="vcage-workers-"))
    cfg = GenerateConfig()
    try:
        rows = []
        for n in [1, *args.workers]:
            funnel = generate(args.instruction, args.episodes, root / f"w{n}",
                              replace(cfg, executor=ExecutorConfig(workers=n)))
            rows.append((n, funnel.to_dict()))
        base = DatasetReader(root / "w1")
        same = all(
            np.array_equal(base.episode(k).arrays["states"],
                           DatasetReader(root / f"w{n}").episode(k).arrays["states"])
            for n in args.workers for k in range(args.episodes))
        print(f"'{args.instruction}', {args.episodes} accepted episodes per run, seed {cfg.seed}, "
              f"{os.cpu_count()} cores; datasets identical across worker counts: {same}\n")
        print(f"{'workers':>7s} {'attempts':>8s} {'wall s':>8s} {'eps/hour':>9s} {'eps/core-h':>10s} "
              f"{'speed-up':>8s}")
        base_wall = rows[0][1]["wall_seconds"]
        for n, s in rows:
            print(f"{n:7d} {s['attempts']:8d} {s['wall_seconds']:8.1f} {s['episodes_per_hour']:9.1f} "
                  f"{s['episodes_per_core_hour']:10.1f} {base_wall / s['wall_seconds']:8.2f}")
    finally:
        shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    main()
