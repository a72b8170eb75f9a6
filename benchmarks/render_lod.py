"""Full versus level-of-detail (LOD) rendering: what a frame costs and what it shows. LOD draws the
robot's heavy visual meshes simplified and primitives tessellated more coarsely
(``vcage.sim.lod.LOD_QUALITY``); "full" draws the model as compiled.

The scene is the standard plan scene: the first accepted attempt of "get ready for work" with the
default generation config (context placement, 4 distractors) and no critic; its recording is the
video pass measured at the end. The arm is put in the home posture and in ``--postures`` seeded
random joint configurations within its limits (fingers random too), and every camera renders each
posture at 128x128 and 320x240 with full and LOD meshes. Printed per camera and size:

- robot IoU: intersection over union of the robot's pixels (segmentation), full vs LOD, pooled over
  the postures (summed intersections over summed unions) and the lowest of one posture among those
  where the robot covers at least 100 pixels (``vis``: how many; a sliver of a few pixels says
  nothing);
- obj IoU: the same pooled IoU for the objects' pixels (each object's label against its own);
- MAD: mean absolute RGB difference (0-255) over all pixels; ``px>16``: share of pixels where a
  channel differs by more than 16;
- ms per frame (update + render + read) with full meshes, LOD meshes, and LOD meshes with the
  geoms batched per body and look (``vcage.sim.batching``, what a run draws), the best of
  ``--rounds`` interleaved rounds measured in the same run, and the ratios full / batched and
  LOD / batched. The IoU and difference columns compare full with batched.

Then the faces drawn, and the video pass of the recording's first ``--video-frames`` states with
the two default cameras: before (``set_state`` with ``mj_forward`` per frame, a render per camera,
full meshes), the same loop with LOD meshes, and after (``Renderer.rgb_states``, LOD); the best of
``--rounds`` interleaved rounds.

    LP_NUM_THREADS=1 .venv/bin/python benchmarks/render_lod.py
"""

from __future__ import annotations

import os

os.environ.setdefault("LP_NUM_THREADS", "1")  # one rasteriser thread: one core

import argparse
import time
from dataclasses import replace

import numpy as np

from vcage.config import CAMERAS, RenderConfig
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.episode import Attempt, attempt
from vcage.planning import make_planner
from vcage.sim import batching, lod
from vcage.sim.render import ROBOT, Renderer
from vcage.sim.robot import GRIPPER_OPEN, HOME_QPOS
from vcage.sim.world import World

SIZES = ((128, 128), (320, 240))
MIN_PIXELS = 100  # a posture's IoU counts towards the minimum from this many robot pixels


def recorded_episode(seed: int) -> Attempt:
    """The first accepted attempt of "get ready for work" (default config, no critic)."""
    plan = make_planner("offline").plan("get ready for work")
    cfg = replace(GenerateConfig(seed=seed), critic=None)
    for j in range(20):
        result = attempt(plan, cfg.episode_seed(0, j), cfg, None)
        if result.accepted:
            return result
    raise SystemExit("no accepted attempt in 20; try another --seed")


def postures(world: World, n: int, seed: int) -> list[np.ndarray]:
    """Simulator states: the home posture and ``n`` random arm and finger configurations."""
    rng = np.random.default_rng(seed)
    robot, base = world.robot, world.get_state()
    lo, hi = robot.arm_limits[:, 0], robot.arm_limits[:, 1]
    configs = [(HOME_QPOS, GRIPPER_OPEN)] + [(rng.uniform(lo, hi), rng.uniform(0, GRIPPER_OPEN))
                                             for _ in range(n)]
    states = []
    for q, finger in configs:
        world.show_state(base)
        world.data.qpos[robot.arm_qpos] = q
        world.data.qpos[robot.finger_qpos] = finger
        states.append(world.get_state())
    world.set_state(base)
    return states


def compare(world: World, states: list[np.ndarray], camera: str, full: Renderer, simple: Renderer,
            unbatched: Renderer, rounds: int) -> str:
    inter = union_all = obj_inter = obj_union = 0
    ious, mads, changed = [], [], []
    for state in states:
        world.show_state(state)
        a, b = full.rgb(camera).astype(np.int16), simple.rgb(camera).astype(np.int16)
        mads.append(np.abs(a - b).mean())
        changed.append((np.abs(a - b).max(axis=-1) > 16).mean())
        sa, sb = full.segmentation(camera) == ROBOT, simple.segmentation(camera) == ROBOT
        union = (sa | sb).sum()
        inter, union_all = inter + (sa & sb).sum(), union_all + union
        if union >= MIN_PIXELS:
            ious.append((sa & sb).sum() / union)
        oa, ob = full.segmentation(camera), simple.segmentation(camera)
        objects = (oa >= 0) | (ob >= 0)
        obj_inter, obj_union = obj_inter + ((oa == ob) & objects).sum(), obj_union + objects.sum()
    ms = {"full": np.inf, "unbatched": np.inf, "lod": np.inf}
    for _ in range(rounds):  # interleaved, so that all see the same load
        for name, renderer in (("full", full), ("unbatched", unbatched), ("lod", simple)):
            spent = 0.0
            for state in states:
                world.show_state(state)
                t0 = time.perf_counter()
                renderer.rgb(camera)
                spent += time.perf_counter() - t0
            ms[name] = min(ms[name], spent / len(states) * 1e3)
    pooled = f"{inter / union_all:8.4f}" if union_all else f"{'n/a':>8s}"
    iou = f"{pooled} {np.min(ious):7.4f}" if ious else f"{pooled} {'n/a':>7s}"
    obj = f"{obj_inter / obj_union:8.4f}" if obj_union else f"{'n/a':>8s}"
    return (f"{iou} {len(ious):4d} {obj} {np.mean(mads):6.2f} {np.mean(changed):7.2%} "
            f"{ms['full']:8.2f} {ms['unbatched']:8.2f} {ms['lod']:8.2f} {ms['full'] / ms['lod']:6.2f}x "
            f"{ms['unbatched'] / ms['lod']:6.2f}x")


def video_pass(world: World, states: np.ndarray, cameras: tuple[str, ...], size: tuple[int, int],
               rounds: int) -> None:
    width, height = size

    def before(detail: str) -> float:
        out = {c: np.empty((len(states), height, width, 3), np.uint8) for c in cameras}
        with Renderer(world, width, height, detail) as r:
            t0 = time.perf_counter()
            for i, state in enumerate(states):
                world.set_state(state)
                for cam in cameras:
                    out[cam][i] = r.rgb(cam)
            return time.perf_counter() - t0

    def after(batch: bool = True) -> float:
        with Renderer(world, width, height, "lod", batch=batch) as r:
            t0 = time.perf_counter()
            r.rgb_states(states, cameras)
            return time.perf_counter() - t0

    current = world.get_state()
    t0 = time.perf_counter()
    for state in states:
        world.set_state(state)
    forward = time.perf_counter() - t0
    t0 = time.perf_counter()
    for state in states:
        world.show_state(state)
    show = time.perf_counter() - t0
    world.set_state(current)
    full = lod_loop = unbatched = new = np.inf
    for _ in range(rounds):  # interleaved; the best of each
        full, lod_loop = min(full, before("full")), min(lod_loop, before("lod"))
        unbatched, new = min(unbatched, after(batch=False)), min(new, after())
    n = len(states)
    print(f"\nvideo pass: {n} recorded states x {len(cameras)} cameras ({', '.join(cameras)}) at "
          f"{width}x{height}, ms per state (all cameras)")
    print(f"  before  set_state (mj_forward) + render per camera, full meshes  {full / n * 1e3:7.2f}")
    print(f"          the same loop with LOD meshes                           {lod_loop / n * 1e3:7.2f}")
    print(f"  after   Renderer.rgb_states (show_state: kinematics only), LOD   {unbatched / n * 1e3:7.2f}")
    print(f"          the same, geoms batched per body and look                {new / n * 1e3:7.2f}"
          f"   ({full / new:.2f}x faster than before, {unbatched / new:.2f}x than unbatched)")
    print(f"  restoring a state: set_state {forward / n * 1e3:.3f} ms, show_state {show / n * 1e3:.3f} ms")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--postures", type=int, default=20, help="random arm postures besides home")
    parser.add_argument("--rounds", type=int, default=3, help="timing rounds; the best is printed")
    parser.add_argument("--budget", type=int, default=lod.FACE_BUDGET, help="faces per simplified mesh")
    parser.add_argument("--video-frames", type=int, default=200, help="recorded states in the video pass")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    lod.FACE_BUDGET = args.budget  # what "lod" renderers of this process draw

    t0 = time.perf_counter()
    result = recorded_episode(args.seed)
    assert result.world is not None and result.recording is not None
    world = result.world
    print(f"MUJOCO_GL={os.environ.get('MUJOCO_GL')} LP_NUM_THREADS={os.environ.get('LP_NUM_THREADS')}; "
          f"plan scene 'get ready for work' seed {result.seed} ({len(world.object_names)} objects), "
          f"{args.postures + 1} postures, face budget {args.budget} per mesh "
          f"(scene ready in {time.perf_counter() - t0:.1f} s)")
    t0 = time.perf_counter()
    simple_model = lod.lod_model(world.model)
    print(f"LOD model (simplified or read from the cache, and copied) in {time.perf_counter() - t0:.2f} s")
    heavy = lod.heavy_visual_meshes(world.model, args.budget)
    full_faces, simple_faces = world.model.mesh_facenum, simple_model.mesh_facenum
    print(f"faces: scene {int(full_faces.sum()):,} -> {int(simple_faces.sum()):,}; the {len(heavy)} "
          f"simplified meshes {int(full_faces[heavy].sum()):,} -> {int(simple_faces[heavy].sum()):,}")
    t0 = time.perf_counter()
    batched_model = batching.batched_model(simple_model, world.spec())[0]
    drawn = [int(np.isin(m.geom_group, batching.DRAWN_GROUPS).sum()) for m in (simple_model, batched_model)]
    print(f"geoms drawn: {drawn[0]} -> {drawn[1]} batched per body and look (compiled in "
          f"{time.perf_counter() - t0:.2f} s)\n")

    states = postures(world, args.postures, args.seed)
    q = world.model.vis.quality
    print(f"primitives (slices, stacks, quads): full {(q.numslices, q.numstacks, q.numquads)}, "
          f"LOD {lod.LOD_QUALITY}\n")
    header = (f"{'camera':12s} {'size':>7s} {'IoU':>8s} {'min':>7s} {'vis':>4s} {'obj IoU':>8s} "
              f"{'MAD':>6s} "
              f"{'px>16':>7s} {'full ms':>8s} {'LOD ms':>8s} {'batched':>8s} {'ratio':>7s} {'batch':>7s}")
    print(header)
    for width, height in SIZES:
        full, simple = Renderer(world, width, height, "full"), Renderer(world, width, height, "lod")
        unbatched = Renderer(world, width, height, "lod", batch=False)
        try:
            for camera in CAMERAS:
                print(f"{camera:12s} {f'{width}x{height}':>7s} "
                      + compare(world, states, camera, full, simple, unbatched, args.rounds))
        finally:
            full.close()
            simple.close()
            unbatched.close()
    recording = np.asarray(result.recording.states)[: args.video_frames]
    video_pass(world, recording, RenderConfig().cameras, RenderConfig().size, args.rounds)


if __name__ == "__main__":
    main()
