"""The reference learner: LeRobot's own diffusion policy, trained on a vcage dataset and rolled out in
vcage's evaluation environment. Question: when our policy fails to learn clean data, is our policy
the bottleneck? The field's reference implementation (LeRobot 0.6.1, state-only configuration: the
joint state and the plan objects' poses in, the 8-dim joint targets + gripper out; no images) is
trained on the same dataset and evaluated on the same held-out scenes and training scenes.

LeRobot runs in its own Python 3.12 environment (``bash scripts/lerobot-env.sh`` builds
``.venv-lerobot/``); this script runs in vcage's ``.venv``, drives ``lerobot-train`` as a
subprocess, and rolls the policy out through ``benchmarks/lerobot_bridge.py`` (a subprocess in
``.venv-lerobot`` that answers actions as JSON lines). Nothing here is needed by the tests or CI.

    .venv/bin/python benchmarks/lerobot_reference.py train --dataset DATASET --steps 20000 \\
        --out /tmp/lerobot_ref/train/run
    .venv/bin/python benchmarks/lerobot_reference.py evaluate --dataset DATASET \\
        --checkpoint /tmp/lerobot_ref/train/run --scenes EVAL.json --episodes 50 --record eval.json

(``evaluate --training-scenes`` rolls out on the dataset's own first ``--episodes`` scenes instead.)

What ``train`` does: LeRobot decodes every video feature of a dataset for every training sample,
whatever the policy reads (about 3x slower per step here), so it first writes a state-only copy of
the dataset with LeRobot's own ``lerobot-edit-dataset --operation.type remove_feature`` (the video and
the features the policy does not read; the copy's frames, stats and episodes are the original's),
then trains ``--policy.type=diffusion`` on it: input features ``observation.state`` and
``observation.environment_state`` (passed explicitly), output ``action``, U-Net ``down_dims``
32,64,128, horizon 16, 2 observation steps, 8 action steps, batch 64; everything else is LeRobot's
default (DDPM with 100 train and inference steps, Adam lr 1e-4 with 500 warm-up steps and a
cosine schedule, min-max normalization, no image augmentation). One core: torch threads 1 and
the data loaded in the training process (``--num_workers=0``). Measured so, on one core: about
0.6 s per training step at batch 64 (three quarters of it LeRobot's data loading), and about a
minute per 600-step rollout (the policy samples a chunk with 100 DDPM steps every 8 control steps,
about 95 ms per control step; the environment about 3 ms).

Caveats: LeRobot 0.6.1 declares torch<2.12, so this runs torch 2.11 (vcage's policy: torch 2.13);
LeRobot's defaults are not vcage's (its noise schedule, inference steps, learning-rate schedule and
normalization differ), so a gap between the two says "LeRobot's recipe at this budget", not "a
diffusion policy"; success counts on a few dozen scenes have wide intervals (Wilson 95% printed);
the diffusion sampling is seeded per episode (``--policy-seed``), and another seed gives other
rollouts; a smoke run (hundreds of steps) only shows the path works: its success figure means
nothing.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path
from typing import IO, Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
VENV = ROOT / ".venv-lerobot"
BRIDGE = ROOT / "benchmarks" / "lerobot_bridge.py"
WORK = Path("/tmp/lerobot_ref")
INPUTS = ("observation.state", "observation.environment_state")
OUTPUT = "action"
DOWN_DIMS = (32, 64, 128)
HORIZON, N_OBS_STEPS, N_ACTION_STEPS = 16, 2, 8


def lerobot_tool(name: str) -> Path:
    path = VENV / "bin" / name
    if not path.exists():
        sys.exit(f"{path} is missing: build the LeRobot environment first (bash scripts/lerobot-env.sh)")
    return path


def lerobot_environ(work: Path) -> dict[str, str]:
    """The LeRobot processes' environment: offline, one thread, caches under ``work``."""
    return {**os.environ, "HF_HUB_OFFLINE": "1", "HF_DATASETS_OFFLINE": "1", "WANDB_MODE": "disabled",
            "HF_HOME": str(work / "hf"), "HF_LEROBOT_HOME": str(work / "hf" / "lerobot"),
            "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}


def dataset_name(dataset: Path) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]", "_", f"{dataset.parent.name}_{dataset.name}")


def read_info(dataset: Path) -> dict[str, Any]:
    info: dict[str, Any] = json.loads((dataset / "meta" / "info.json").read_text())
    return info


def state_only_copy(dataset: Path, work: Path) -> Path:
    """A copy of ``dataset`` without the features the policy does not read (videos above all), made by
    LeRobot's own dataset editor; reused when it is there."""
    name = dataset_name(dataset)
    copy = work / "data" / f"{name}_state"
    if (copy / "meta" / "info.json").exists():
        return copy
    features = read_info(dataset)["features"]
    drop = [key for key, ft in features.items()
            if key not in (*INPUTS, OUTPUT) and (key.startswith(("observation.", "action")) or
                                                ft.get("dtype") in ("video", "image"))]
    copy.parent.mkdir(parents=True, exist_ok=True)
    command = [str(lerobot_tool("lerobot-edit-dataset")), f"--repo_id=local/{name}", f"--root={dataset}",
               f"--new_repo_id=local/{name}_state", f"--new_root={copy}",
               "--operation.type=remove_feature", f"--operation.feature_names={json.dumps(drop)}"]
    print(f"state-only copy of the dataset (dropping {', '.join(drop)}): {copy}", flush=True)
    log = work / "logs" / f"{name}_state.log"
    log.parent.mkdir(parents=True, exist_ok=True)
    with log.open("w") as out:
        done = subprocess.run(command, stdout=out, stderr=subprocess.STDOUT, env=lerobot_environ(work))
    if done.returncode != 0 or not (copy / "meta" / "info.json").exists():
        sys.exit(f"lerobot-edit-dataset failed ({done.returncode}); see {log}")
    kept = read_info(copy)
    if kept["total_frames"] != read_info(dataset)["total_frames"]:
        sys.exit(f"the state-only copy has {kept['total_frames']} frames, the dataset more; see {log}")
    return copy


def train_command(data: Path, name: str, out: Path, steps: int, batch: int, seed: int) -> list[str]:
    features = {"observation.state": "STATE", "observation.environment_state": "ENV"}
    shapes = read_info(data)["features"]
    input_features = {key: {"type": kind, "shape": shapes[key]["shape"]} for key, kind in features.items()}
    return [str(lerobot_tool("lerobot-train")),
            "--policy.type=diffusion", f"--dataset.repo_id=local/{name}", f"--dataset.root={data}",
            "--dataset.video_backend=pyav", "--policy.device=cpu", "--policy.push_to_hub=false",
            f"--policy.input_features={json.dumps(input_features)}",
            f"--policy.down_dims={json.dumps(list(DOWN_DIMS))}", f"--policy.horizon={HORIZON}",
            f"--policy.n_obs_steps={N_OBS_STEPS}", f"--policy.n_action_steps={N_ACTION_STEPS}",
            f"--batch_size={batch}", f"--steps={steps}", f"--seed={seed}", "--num_workers=0",
            f"--log_freq={max(1, min(200, steps // 10))}", f"--save_freq={steps}", "--wandb.enable=false",
            f"--output_dir={out}"]


LOG_LINE = re.compile(r"step:(\S+) .*?loss:(\S+) .*?updt_s:(\S+) data_s:(\S+)")


def train(args: argparse.Namespace) -> dict[str, Any]:
    dataset = args.dataset.resolve()
    frames = read_info(dataset)["total_frames"]
    data = state_only_copy(dataset, args.work)
    name = f"{dataset_name(dataset)}_state"
    out = args.out or args.work / "train" / f"{dataset_name(dataset)}-seed{args.seed}-{args.steps}"
    if out.exists():
        sys.exit(f"{out} exists (lerobot-train refuses to overwrite a run): pass another --out")
    out.parent.mkdir(parents=True, exist_ok=True)
    command = train_command(data, name, out, args.steps, args.batch, args.seed)
    passes = args.steps * args.batch / frames
    print(f"training LeRobot diffusion: {args.steps} steps x batch {args.batch} over {frames} frames "
          f"= {passes:.2f} passes over the data; log: {out}.log", flush=True)
    start = time.perf_counter()
    with Path(f"{out}.log").open("w") as log:
        done = subprocess.run(command, stdout=log, stderr=subprocess.STDOUT, env=lerobot_environ(args.work))
    seconds = time.perf_counter() - start
    text = Path(f"{out}.log").read_text(errors="replace")
    if done.returncode != 0:
        sys.exit(f"lerobot-train failed ({done.returncode}); the end of {out}.log:\n{text[-3000:]}")
    logged = [(int(_number(s)), float(loss), float(u), float(d)) for s, loss, u, d in LOG_LINE.findall(text)]
    step_s = [u + d for _, _, u, d in logged]
    checkpoint = out / "checkpoints" / "last" / "pretrained_model"
    print(f"done in {seconds:.0f} s ({seconds / args.steps:.3f} s per step with start-up and saving"
          + (f"; {np.mean(step_s):.3f} s per logged step: {np.mean([x[2] for x in logged]):.3f} update, "
             f"{np.mean([x[3] for x in logged]):.3f} data" if logged else "") + ")")
    if logged:
        print("loss: " + ", ".join(f"{s}: {loss:.3f}" for s, loss, _, _ in logged))
    print(f"checkpoint: {checkpoint}")
    return {"kind": "train", "checkpoint": str(checkpoint), "dataset": str(dataset),
            "state_only_copy": str(data), "steps": args.steps, "batch": args.batch, "frames": frames,
            "passes": passes, "seed": args.seed, "seconds": seconds, "seconds_per_step": seconds / args.steps,
            "logged": [{"step": s, "loss": loss, "update_s": u, "data_s": d} for s, loss, u, d in logged],
            "lerobot_command": command}


def _number(text: str) -> float:
    """LeRobot logs big numbers as '1K', '2M'."""
    scale = {"K": 1e3, "M": 1e6, "B": 1e9}.get(text[-1:], 1.0)
    return float(text[:-1] if scale != 1.0 else text) * scale


class BridgeProcess:
    """``lerobot_bridge.py`` in ``.venv-lerobot``, spoken to in JSON lines."""

    def __init__(self, checkpoint: Path, seed: int, work: Path, log: IO[str]) -> None:
        self.process = subprocess.Popen(
            [str(lerobot_tool("python")), str(BRIDGE), str(checkpoint), "--seed", str(seed)],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=log, text=True, bufsize=1,
            env=lerobot_environ(work))
        self.banner = self._read()
        if not self.banner.get("ready"):
            raise RuntimeError(f"the bridge did not start: {self.banner}")
        self.features: list[str] = list(self.banner["input_features"])

    def _read(self) -> dict[str, Any]:
        assert self.process.stdout is not None
        line = self.process.stdout.readline()
        if not line:
            raise RuntimeError(f"the bridge exited ({self.process.wait()}); see its log")
        reply: dict[str, Any] = json.loads(line)
        if "error" in reply:
            raise RuntimeError(f"the bridge: {reply['error']}")
        return reply

    def ask(self, request: dict[str, Any]) -> dict[str, Any]:
        assert self.process.stdin is not None
        self.process.stdin.write(json.dumps(request) + "\n")
        self.process.stdin.flush()
        return self._read()

    def reset(self, episode: int) -> None:
        self.ask({"reset": True, "episode": episode})

    def act(self, obs: dict[str, np.ndarray]) -> np.ndarray:
        reply = self.ask({"observation": {key: np.asarray(obs[key], dtype=float).tolist()
                                          for key in self.features}})
        return np.asarray(reply["action"], dtype=np.float32)

    def close(self) -> None:
        if self.process.stdin is not None:
            self.process.stdin.close()
        self.process.wait(timeout=60)


def resolve_checkpoint(path: Path) -> Path:
    for candidate in (path, path / "pretrained_model", path / "checkpoints" / "last" / "pretrained_model"):
        if (candidate / "config.json").exists() and (candidate / "model.safetensors").exists():
            return candidate.resolve()
    sys.exit(f"{path}: no LeRobot pretrained_model there (a lerobot-train --output_dir, a checkpoint "
             "or its pretrained_model directory)")


def evaluate(args: argparse.Namespace) -> dict[str, Any]:
    from vcage.cli.evaluate import read_scenes
    from vcage.data import DatasetReader
    from vcage.pipeline.evaluation import make_env
    from vcage.policy.evaluate import dataset_scenes
    from vcage.policy.metrics import wilson_interval

    checkpoint = resolve_checkpoint(args.checkpoint)
    reader = DatasetReader(args.dataset)
    assert reader.config is not None, f"{args.dataset} is not a vcage dataset (no meta/vcage.json config)"
    if args.training_scenes:
        scenes = dataset_scenes(args.dataset, args.episodes)
        where = "training scenes"
    else:
        if args.scenes is None:
            sys.exit("pass --scenes FILE (held-out scene seeds) or --training-scenes")
        scenes = read_scenes(args.scenes)[:args.episodes]
        where = f"held-out scenes of {args.scenes}"
    if len(scenes) < args.episodes:
        sys.exit(f"--episodes {args.episodes}: only {len(scenes)} {where}")
    trained = json.loads((checkpoint / "train_config.json").read_text())
    steps, batch = int(trained["steps"]), int(trained["batch_size"])
    frames = read_info(Path(trained["dataset"]["root"]))["total_frames"]
    env = make_env(reader.config, scenes=scenes, action=OUTPUT, max_steps=args.max_steps)
    log_path = args.work / "logs" / f"bridge-{int(time.time())}.log"
    log_path.parent.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    episodes: list[dict[str, Any]] = []
    with log_path.open("w") as log:
        bridge = BridgeProcess(checkpoint, args.policy_seed, args.work, log)
        started = time.perf_counter() - start
        print(f"LeRobot {bridge.banner['lerobot']} (torch {bridge.banner['torch']}) {bridge.banner['type']} "
              f"policy reading {', '.join(bridge.features)}; {steps} steps x batch {batch} = "
              f"{steps * batch / frames:.2f} passes; bridge up in {started:.1f} s", flush=True)
        try:
            for k, scene in enumerate(scenes):
                t0 = time.perf_counter()
                obs, info = env.reset(seed=args.eval_seed, options={"episode": k})
                bridge.reset(k)
                policy_s, n, terminated, truncated = 0.0, 0, False, False
                while not (terminated or truncated):
                    t1 = time.perf_counter()
                    action = bridge.act(obs)
                    policy_s += time.perf_counter() - t1
                    obs, _, terminated, truncated, info = env.step(action)
                    n += 1
                seconds = time.perf_counter() - t0
                episodes.append({"episode": k, "scene": scene, "success": bool(info["success"]), "steps": n,
                                 "seconds": seconds, "policy_seconds": policy_s})
                print(f"  episode {k} scene {scene}: {'success' if info['success'] else 'failure'} after "
                      f"{n} steps, {seconds:.1f} s ({policy_s:.1f} s in the policy)", flush=True)
        finally:
            bridge.close()
    wall = time.perf_counter() - start
    successes = sum(e["success"] for e in episodes)
    low, high = wilson_interval(successes, len(episodes))
    control_steps = sum(e["steps"] for e in episodes)
    rollout_s = float(np.mean([e["seconds"] for e in episodes]))
    policy_ms = 1e3 * sum(e["policy_seconds"] for e in episodes) / control_steps
    env_ms = 1e3 * sum(e["seconds"] - e["policy_seconds"] for e in episodes) / control_steps
    print(f"{where}: {successes}/{len(episodes)} successes, Wilson 95% [{low:.2f}, {high:.2f}]; "
          f"wall {wall:.0f} s, {rollout_s:.1f} s per rollout ({policy_ms:.1f} ms per step in the policy, "
          f"{env_ms:.1f} ms in the environment)")
    return {"kind": "evaluate", "checkpoint": str(checkpoint), "dataset": str(args.dataset), "where": where,
            "lerobot": bridge.banner["lerobot"], "torch": bridge.banner["torch"],
            "input_features": bridge.features, "steps": steps, "batch": batch, "frames": frames,
            "passes": steps * batch / frames, "eval_seed": args.eval_seed, "policy_seed": args.policy_seed,
            "successes": successes, "n": len(episodes), "wilson95": [low, high], "wall_seconds": wall,
            "seconds_per_rollout": rollout_s, "policy_ms_per_step": policy_ms, "env_ms_per_step": env_ms,
            "episodes": episodes}


def lerobot_version() -> str | None:
    try:
        done = subprocess.run([str(VENV / "bin" / "python"), "-c",
                               "import importlib.metadata as m; print(m.version('lerobot'))"],
                              capture_output=True, text=True, timeout=120)
    except OSError:
        return None
    return done.stdout.strip() or None


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--work", type=Path, default=WORK,
                        help="state-only dataset copies, runs, logs, caches")
    common.add_argument("--record", type=Path, help="write the command, versions, budget and figures here")
    sub = parser.add_subparsers(dest="command", required=True)
    tr = sub.add_parser("train", parents=[common], help="train LeRobot's diffusion policy on a vcage dataset")
    tr.add_argument("--dataset", type=Path, required=True, help="a vcage dataset (LeRobot v3 layout)")
    tr.add_argument("--steps", type=int, default=20_000)
    tr.add_argument("--batch", type=int, default=64)
    tr.add_argument("--seed", type=int, default=0)
    tr.add_argument("--out", type=Path, help="lerobot-train's --output_dir (must not exist)")
    ev = sub.add_parser("evaluate", parents=[common],
                        help="roll the trained policy out in vcage's evaluation environment")
    ev.add_argument("--dataset", type=Path, required=True, help="the vcage dataset it was trained on")
    ev.add_argument("--checkpoint", type=Path, required=True,
                    help="a lerobot-train --output_dir, a checkpoint or its pretrained_model directory")
    ev.add_argument("--scenes", type=Path, help="held-out scene seeds (JSON, as `vcage evaluate --scenes`)")
    ev.add_argument("--training-scenes", action="store_true", help="the dataset's first --episodes scenes")
    ev.add_argument("--episodes", type=int, default=10)
    ev.add_argument("--eval-seed", type=int, default=0, help="the environment's reset seed")
    ev.add_argument("--policy-seed", type=int, default=0, help="the diffusion sampling's seed (per episode)")
    ev.add_argument("--max-steps", type=int, help="control steps per episode at most (default: the env's)")
    args = parser.parse_args(argv)
    args.work.mkdir(parents=True, exist_ok=True)
    result = train(args) if args.command == "train" else evaluate(args)
    if args.record:
        record = {"command": " ".join([".venv/bin/python", "benchmarks/lerobot_reference.py",
                                       *(argv if argv is not None else sys.argv[1:])]),
                  "lerobot_version": lerobot_version(), "date": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
                  **result}
        args.record.parent.mkdir(parents=True, exist_ok=True)
        args.record.write_text(json.dumps(record, indent=1) + "\n")
        print(f"record: {args.record}")


if __name__ == "__main__":
    main()
