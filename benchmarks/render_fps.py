"""Offscreen render throughput per camera at 128x128 and 320x240, on one rendering thread.

    .venv/bin/python benchmarks/render_fps.py

Uses dataset quality (no shadows, no multisampling). ``LP_NUM_THREADS=1`` keeps Mesa's software
rasteriser (llvmpipe) on one core; on a machine with a GPU and EGL the figures are the GPU's.
"""

from __future__ import annotations

import os

os.environ.setdefault("LP_NUM_THREADS", "1")

import time

from vcage.config import Randomization
from vcage.sim.render import Renderer
from vcage.tasks import prepare

CAMERAS = ("front", "overview", "top", "panda/wrist")
SIZES = ((128, 128), (320, 240))
FRAMES = 100


def main() -> None:
    _, world, _ = prepare("stack_blocks_three", 0, Randomization.off())
    print(f"MUJOCO_GL={os.environ.get('MUJOCO_GL')} LP_NUM_THREADS={os.environ.get('LP_NUM_THREADS')}; "
          f"scene stack_blocks_three with the Panda; {FRAMES} frames each\n")
    print(f"{'camera':14s}" + "".join(f"{f'{w}x{h} fps':>14s}" for w, h in SIZES)
          + f"{'seg 128 fps':>14s}")
    for cam in CAMERAS:
        row = f"{cam:14s}"
        for w, h in SIZES:
            with Renderer(world, w, h) as r:
                r.rgb(cam)
                t0 = time.perf_counter()
                for _ in range(FRAMES):
                    r.rgb(cam)
                row += f"{FRAMES / (time.perf_counter() - t0):14.0f}"
        with Renderer(world, 128, 128) as r:
            r.segmentation(cam)
            t0 = time.perf_counter()
            for _ in range(FRAMES):
                r.segmentation(cam)
            row += f"{FRAMES / (time.perf_counter() - t0):14.0f}"
        print(row)


if __name__ == "__main__":
    main()
