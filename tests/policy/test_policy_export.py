"""Moving a policy trained elsewhere: checkpoints exported for evaluation, and training where the
simulator and the video codec are not installed (a GPU machine that only trains)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import torch

from conftest import blocked_modules, tiny
from vcage.policy.checkpoint import EVALUATION_ONLY, export_for_evaluation, load_checkpoint
from vcage.policy.errors import CheckpointError
from vcage.policy.inference import PolicyRunner
from vcage.policy.train import train

SRC = Path(__file__).resolve().parents[2] / "src"


def actions(checkpoint: dict, obs: dict[str, np.ndarray], steps: int) -> np.ndarray:
    runner = PolicyRunner(checkpoint, seed=3)
    runner.reset(seed=3)
    return np.stack([runner.act(obs) for _ in range(steps)])


def test_an_exported_checkpoint_acts_like_its_source_and_cannot_resume(dataset: Path, tmp_path: Path) -> None:
    run = tmp_path / "run"
    summary = train(dataset, run, tiny("diffusion", steps=20))
    exported = export_for_evaluation(summary.checkpoint, tmp_path / "moved.pt", trained={"seconds": 1.5})
    source, moved = load_checkpoint(summary.checkpoint), load_checkpoint(exported)
    assert moved[EVALUATION_ONLY] is True and moved["trained"] == {"seconds": 1.5}
    assert not {"model", "optimizer", "rng", "sampler"} & set(moved)
    assert moved["step"] == source["step"] == 20 and moved["dataset"] == source["dataset"]
    assert exported.stat().st_size < 0.5 * summary.checkpoint.stat().st_size
    obs = {f["name"]: np.full(f["size"], 0.1, dtype=np.float32) for f in source["obs_features"]}
    np.testing.assert_array_equal(actions(source, obs, 10), actions(moved, obs, 10))
    # in a run directory it is found, and resuming from it is refused with the reason
    (run / "checkpoints" / exported.name).unlink(missing_ok=True)
    for old in (run / "checkpoints").iterdir():
        old.unlink()
    (run / "checkpoints" / "step-00000020.pt").write_bytes(exported.read_bytes())
    with pytest.raises(CheckpointError, match="exported for evaluation"):
        train(dataset, run, tiny("diffusion", steps=40), resume=True)


def test_an_exported_checkpoint_missing_its_ema_is_refused(dataset: Path, tmp_path: Path) -> None:
    summary = train(dataset, tmp_path / "run", tiny("mlp", steps=5))
    exported = export_for_evaluation(summary.checkpoint, tmp_path / "moved.pt")
    payload = torch.load(exported, weights_only=True)
    del payload["ema"]
    torch.save(payload, exported)
    with pytest.raises(CheckpointError, match="lacks ema"):
        load_checkpoint(exported)


@pytest.mark.slow
def test_training_needs_neither_the_simulator_nor_the_video_codec(dataset: Path, tmp_path: Path) -> None:
    blocked = blocked_modules(tmp_path / "blocked")
    code = ("import sys; from vcage.policy.train import train; from vcage.policy.config import TrainConfig, "
            "DiffusionConfig; c = TrainConfig(steps=3, batch_size=8, checkpoint_every=3, "
            "diffusion=DiffusionConfig(down_dims=(16, 32), n_groups=4, step_embed_dim=16)); "
            f"s = train({str(dataset)!r}, {str(tmp_path / 'run')!r}, c); print(s.steps, "
            "sorted(m for m in ('mujoco', 'av') if m in sys.modules))")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(blocked), str(SRC)])}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["3", "[]"]
