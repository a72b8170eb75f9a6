"""The training step on a GPU, eager against captured as a CUDA graph (``vcage train --cuda-graph``).

Prints, for one dataset and the policy experiment's configuration (diffusion U-Net 32-64-128, tool
pose predicted from the tool pose and the objects):

1. steps per second of one run alone, eager and graphed, at ``--batches`` (``--steps`` each, the
   graph's warm-up and capture included), and how far the graphed run's EMA weights and per-step
   losses are from the eager run's after the same steps and draws (a GPU's eager run is not
   bit-reproducible either: this shows the size of the difference, not its cause);
2. ``--together`` graphed runs at once (each its own process, as the experiment trains), batch
   ``--batches``' last, steps per second each and in all;
3. one longer graphed run (``--long`` steps at the first batch) and its final loss.

Needs CUDA; on a machine without it only the eager lines print.

    python3 benchmarks/train_step_gpu.py --dataset DATASET [--batches 256 1024] [--together 8 16]
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import time
from pathlib import Path

import torch

OBS = ("observation.ee_pose", "observation.environment_state")


def run(dataset: str, out: Path, steps: int, batch: int, graph: bool, seed: int = 0) -> dict:
    from vcage.policy.checkpoint import latest_checkpoint, load_checkpoint
    from vcage.policy.config import TrainConfig
    from vcage.policy.train import train

    shutil.rmtree(out, ignore_errors=True)
    config = TrainConfig(steps=steps, batch_size=batch, checkpoint_every=steps, seed=seed,
                         action_key="action.ee_pose", observation_keys=OBS)
    device = "cuda" if torch.cuda.is_available() else "cpu"
    s = train(dataset, out, config, device=device, threads=1, graph=graph)
    print(f"{'graph' if graph else 'eager'} batch {batch} seed {seed}: {s.steps} steps in {s.seconds:.1f} s "
          f"= {s.steps / s.seconds:.1f} steps/s ({s.samples_per_second:,.0f} samples/s), final loss "
          f"{s.final_loss:.4f}", flush=True)
    payload = load_checkpoint(latest_checkpoint(out))
    return {"rate": s.steps / s.seconds, "ema": payload["ema"]["model"], "losses": payload["loss_history"]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--dataset", required=True)
    parser.add_argument("--batches", type=int, nargs="+", default=[256, 1024])
    parser.add_argument("--steps", type=int, default=200)
    parser.add_argument("--together", type=int, nargs="*", default=[8, 16])
    parser.add_argument("--long", type=int, default=3000)
    parser.add_argument("--work", type=Path, default=Path("/tmp/train-step-gpu"))
    # one of the runs at once: its seed, steps and batch
    parser.add_argument("--child", type=int, nargs=3, default=None, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child is not None:
        seed, steps, batch = args.child
        run(args.dataset, args.work / f"child{seed}", steps, batch, True, seed)
        return
    graphs = torch.cuda.is_available()
    if graphs:
        print(torch.cuda.get_device_name(), f"torch {torch.__version__}", flush=True)
    alone = {}
    for batch in args.batches:
        eager = run(args.dataset, args.work / f"eager{batch}", args.steps, batch, False)
        if not graphs:
            continue
        graphed = run(args.dataset, args.work / f"graph{batch}", args.steps, batch, True)
        alone[batch] = graphed["rate"]
        weights = max((eager["ema"][k] - graphed["ema"][k]).abs().max().item() for k in eager["ema"])
        largest = max(v.abs().max().item() for v in eager["ema"].values())
        losses = (eager["losses"] - graphed["losses"]).abs().max().item()
        print(f"batch {batch}: graph {graphed['rate'] / eager['rate']:.1f}x the eager steps/s; after "
              f"{args.steps} steps the EMA weights differ by at most {weights:.2e} (largest weight "
              f"{largest:.2f}), the per-step losses by at most {losses:.2e}", flush=True)
    if not graphs:
        print("no CUDA device: the graphed step was not measured")
        return
    batch = args.batches[-1]
    for n in args.together:
        # about 5 s alone, n times that if they serialise
        steps = max(100, int(alone[batch] * 5) // 100 * 100)
        began = time.perf_counter()
        child = [sys.executable, __file__, "--dataset", args.dataset, "--work", str(args.work), "--child"]
        procs = [subprocess.Popen([*child, str(i), str(steps), str(batch)]) for i in range(n)]
        codes = {p.wait() for p in procs}
        wall = time.perf_counter() - began
        print(f"{n} graphed runs at once, batch {batch}, {steps} steps each: {wall:.1f} s wall with "
              f"start-up, {n * steps / wall:.0f} steps/s in all at least; exit codes {codes}", flush=True)
    run(args.dataset, args.work / "long", args.long, args.batches[0], True)


if __name__ == "__main__":
    main()
