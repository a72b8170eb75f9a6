"""What packing many episodes per data and video file costs the writer, against a file per episode.

Writes the same synthetic episodes (two 128x128 cameras, ``--frames`` frames each, moving shapes
that compress to about the size of vcage's rendered frames) into datasets packed at several video
file limits and into one with a file per episode (the baseline, measured in the same run), and
prints the writer's seconds per episode (mean over all, and over the last tenth, when the open
files are largest), the ratio to the baseline, and the files per camera. Appending to a shared
file rewrites it (parquet rows concatenated, video packets copied), so its cost grows with the
file: the limit trades files per camera against seconds per episode.

    .venv/bin/python benchmarks/packing.py --episodes 120 --limits 5 10 50 200
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from vcage.data import DatasetWriter, Feature

FPS = 20
CAMERAS = ("observation.images.front", "observation.images.wrist")
FEATURES = {"observation.state": Feature("float32", (8,)), "observation.ee_pose": Feature("float32", (7,)),
            "action": Feature("float32", (8,))}


def episode(frames: int, seed: int) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:128, 0:128]
    videos = {}
    for c, key in enumerate(CAMERAS):
        base = np.stack([(xx + 40 * c) % 256, (yy * 2) % 256, np.full_like(xx, 90)], -1).astype(np.int16)
        stack = np.empty((frames, 128, 128, 3), np.uint8)
        for t in range(frames):
            cx, cy = 64 + 40 * np.sin(t / 30 + seed), 64 + 30 * np.cos(t / 45 + c)
            blob = ((xx - cx) ** 2 + (yy - cy) ** 2 < 150)[..., None] * np.array([120, -60, 40])
            noise = rng.integers(-6, 7, size=(128, 128, 1))
            stack[t] = np.clip(base + blob + noise, 0, 255)
        videos[key] = stack
    vectors = {key: rng.normal(size=(frames, f.shape[0])).astype(np.float32) for key, f in FEATURES.items()}
    return vectors, videos


def run(root: Path, episodes: list[tuple[dict[str, np.ndarray], dict[str, np.ndarray]]],
        video_mb: float) -> tuple[list[float], int]:
    times = []
    with DatasetWriter(root, fps=FPS, features=FEATURES, cameras=dict.fromkeys(CAMERAS, (128, 128)),
                       config={"bench": "packing"}, video_files_size_in_mb=video_mb,
                       data_files_size_in_mb=video_mb) as writer:
        for i, (vectors, videos) in enumerate(episodes):
            t0 = time.perf_counter()
            writer.add_episode(vectors, videos, task="bench", extras={"seed": i},
                               arrays={"states": np.zeros((len(videos[CAMERAS[0]]), 40))})
            times.append(time.perf_counter() - t0)
    return times, len(list((root / "videos" / CAMERAS[0]).rglob("*.mp4")))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--episodes", type=int, default=120)
    parser.add_argument("--frames", type=int, default=600, help="frames per episode (vcage's are 300-900)")
    parser.add_argument("--limits", type=float, nargs="+", default=[5.0, 10.0, 50.0, 200.0],
                        help="video file limits in MB to compare")
    args = parser.parse_args()
    distinct = [episode(args.frames, seed) for seed in range(8)]
    episodes = [distinct[i % len(distinct)] for i in range(args.episodes)]
    work = Path(tempfile.mkdtemp(prefix="vcage-packing-"))
    try:
        base, files = run(work / "baseline", episodes, 1e-6)
        size = sum(p.stat().st_size for p in (work / "baseline/videos" / CAMERAS[0]).rglob("*.mp4"))
        print(f"{args.episodes} episodes of {args.frames} frames, two 128x128 cameras; "
              f"{size / args.episodes / 2**20:.2f} MB of video per episode and camera")
        tail = max(1, args.episodes // 10)
        print(f"{'video file limit':>18} {'files/camera':>13} {'s/episode':>10} {'last tenth':>11} "
              f"{'ratio':>7} {'last-tenth ratio':>17}")
        mean, last = float(np.mean(base)), float(np.mean(base[-tail:]))
        print(f"{'file per episode':>18} {files:>13} {mean:>10.3f} {last:>11.3f} {1.0:>7.2f} {1.0:>17.2f}")
        for limit in args.limits:
            times, files = run(work / f"packed-{limit}", episodes, limit)
            m, lt = float(np.mean(times)), float(np.mean(times[-tail:]))
            print(f"{limit:>15.0f} MB {files:>13} {m:>10.3f} {lt:>11.3f} {m / mean:>7.2f} {lt / last:>17.2f}")
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
