"""What the integrity checks cost on a packed dataset: ``check`` (no decoding; since content digests,
it hashes every episode's rows, packets, extras and states) and ``verify`` (every video decoded too).

Writes ``--episodes`` synthetic episodes (two 128x128 cameras, the frames of ``packing.py``) into one
dataset at the default file limits, then times each check ``--repeats`` times and prints the
fastest, in seconds and in seconds per GB of the dataset's files. Run it against another revision's
``src`` with ``PYTHONPATH`` to compare (the writer of that revision writes its own dataset):

    LP_NUM_THREADS=1 .venv/bin/python benchmarks/integrity.py --episodes 30
    PYTHONPATH=/tmp/old/src LP_NUM_THREADS=1 .venv/bin/python benchmarks/integrity.py --episodes 30
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

import vcage
from packing import CAMERAS, FEATURES, FPS, episode
from vcage.data import DatasetWriter
from vcage.data.verify import check, verify


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--episodes", type=int, default=30)
    parser.add_argument("--frames", type=int, default=600)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    distinct = [episode(args.frames, seed) for seed in range(8)]
    work = Path(tempfile.mkdtemp(prefix="vcage-integrity-"))
    try:
        root = work / "ds"
        with DatasetWriter(root, fps=FPS, features=FEATURES, cameras=dict.fromkeys(CAMERAS, (128, 128)),
                           config={"bench": "integrity"}) as writer:
            for i in range(args.episodes):
                vectors, videos = distinct[i % len(distinct)]
                writer.add_episode(vectors, videos, task="bench", extras={"seed": i},
                                   arrays={"states": np.zeros((args.frames, 40))})
        size = sum(p.stat().st_size for p in root.rglob("*") if p.is_file())
        print(f"vcage {vcage.__file__}: {args.episodes} episodes of {args.frames} frames, two 128x128 "
              f"cameras, {size / 2**20:.1f} MB")
        for name, run in (("check", check), ("verify", verify)):
            best = float("inf")
            for _ in range(args.repeats):
                t0 = time.perf_counter()
                report = run(root)
                best = min(best, time.perf_counter() - t0)
            assert report.ok, report.summary()
            print(f"  {name:7s} {best:7.3f} s  {best / (size / 2**30):7.1f} s/GB  "
                  f"{best / args.episodes * 1000:7.1f} ms/episode")
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
