"""Training: both policies fit a small dataset; runs are deterministic, resumable and stop on NaN."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch

from conftest import tiny, write_dataset
from vcage.errors import ConfigError
from vcage.policy.checkpoint import checkpoints, load_checkpoint
from vcage.policy.config import DiffusionConfig
from vcage.policy.dataset import load_training_data
from vcage.policy.errors import CheckpointError, PolicyError, TrainingDivergedError
from vcage.policy.inference import PolicyRunner
from vcage.policy.models import MlpPolicy
from vcage.policy.train import train
from vcage.policy.windows import make_windows


def losses(checkpoint: Path) -> torch.Tensor:
    return load_checkpoint(checkpoint)["loss_history"]


def same_weights(a: Path, b: Path) -> bool:
    wa, wb = load_checkpoint(a), load_checkpoint(b)
    return all(torch.equal(wa[part][k], wb[part][k]) for part in ("model",) for k in wa[part]) and \
        all(torch.equal(wa["ema"]["model"][k], wb["ema"]["model"][k]) for k in wa["ema"]["model"])


def test_the_mlp_overfits_a_small_dataset(dataset: Path, tmp_path: Path) -> None:
    summary = train(dataset, tmp_path / "run", tiny("mlp", steps=300, checkpoint_every=300))
    history = losses(summary.checkpoint)
    assert len(history) == 300 and summary.steps == 300
    assert history[:10].mean() > 10 * history[-30:].mean()
    assert summary.samples_per_second > 0 and summary.parameters > 0


@pytest.mark.slow
def test_the_diffusion_policy_overfits_a_small_dataset(dataset: Path, tmp_path: Path) -> None:
    # one U-Net level learns fastest (the multi-level U-Net is exercised by the other tests)
    config = tiny("diffusion", steps=300, checkpoint_every=300, lr=1e-2,
                  diffusion=DiffusionConfig(down_dims=(16,), n_groups=4, step_embed_dim=16,
                                            kernel_size=3, inference_steps=5))
    checkpoint = train(dataset, tmp_path / "run", config).checkpoint
    history = losses(checkpoint)
    assert history[:10].mean() > 5 * history[-30:].mean()
    # and it learned from the observations: their own observations denoise the chunks far better
    runner = PolicyRunner(load_checkpoint(checkpoint))
    data = load_training_data(dataset, config)
    windows = make_windows(data.lengths, 2, 16)
    rows = np.arange(0, len(windows), 3)
    obs = torch.from_numpy(runner.obs_norm.normalize(data.obs)[windows.obs[rows]])
    action = torch.from_numpy(runner.action_norm.normalize(data.action)[windows.action[rows]])
    shuffled = obs[torch.randperm(len(obs), generator=torch.Generator().manual_seed(0))]
    with torch.no_grad():
        matched = runner.model.loss(obs, action, torch.Generator().manual_seed(5))
        mismatched = runner.model.loss(shuffled, action, torch.Generator().manual_seed(5))
    assert mismatched > 2 * matched


@pytest.mark.parametrize("policy", ["diffusion", "mlp"])
def test_the_same_seed_gives_the_same_weights(dataset: Path, tmp_path: Path, policy: str) -> None:
    a = train(dataset, tmp_path / "a", tiny(policy, steps=12, checkpoint_every=12)).checkpoint
    b = train(dataset, tmp_path / "b", tiny(policy, steps=12, checkpoint_every=12)).checkpoint
    c = train(dataset, tmp_path / "c", tiny(policy, steps=12, checkpoint_every=12, seed=1)).checkpoint
    assert same_weights(a, b)
    assert not same_weights(a, c)


@pytest.mark.parametrize("policy", ["diffusion", "mlp"])
def test_a_resumed_run_ends_with_the_weights_of_an_uninterrupted_one(dataset: Path, tmp_path: Path,
                                                                      policy: str) -> None:
    config = tiny(policy, steps=20, checkpoint_every=7)
    whole = train(dataset, tmp_path / "whole", config).checkpoint

    def interrupt(step: int, total: int, loss: float) -> None:
        if step == 17:  # between the checkpoints of steps 14 and 21
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        train(dataset, tmp_path / "cut", config, progress=interrupt)
    assert [p.name for p in checkpoints(tmp_path / "cut")] == ["step-00000007.pt", "step-00000014.pt"]
    resumed = train(dataset, tmp_path / "cut", config, resume=True)
    assert resumed.start_step == 14 and resumed.steps == 20
    assert same_weights(whole, resumed.checkpoint)
    assert torch.equal(losses(whole), losses(resumed.checkpoint))
    assert [p.name for p in checkpoints(tmp_path / "cut")] == [
        "step-00000007.pt", "step-00000014.pt", "step-00000020.pt"]


def test_a_run_that_keeps_two_checkpoints_deletes_the_older_ones_and_still_resumes(dataset: Path,
                                                                                   tmp_path: Path) -> None:
    config = tiny("mlp", steps=10, checkpoint_every=2)
    whole = train(dataset, tmp_path / "whole", config).checkpoint
    assert len(checkpoints(tmp_path / "whole")) == 5  # every checkpoint, by default

    def interrupt(step: int, total: int, loss: float) -> None:
        if step == 7:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        train(dataset, tmp_path / "cut", config, progress=interrupt, keep=2)
    assert [p.name for p in checkpoints(tmp_path / "cut")] == ["step-00000004.pt", "step-00000006.pt"]
    resumed = train(dataset, tmp_path / "cut", config, resume=True, keep=2)
    assert [p.name for p in checkpoints(tmp_path / "cut")] == ["step-00000008.pt", "step-00000010.pt"]
    assert same_weights(whole, resumed.checkpoint)
    with pytest.raises(ConfigError, match="keep-checkpoints"):
        train(dataset, tmp_path / "other", config, keep=0)
    assert not (tmp_path / "other").exists()


def test_resume_starts_afresh_in_an_empty_directory_and_refuses_another_config(dataset: Path,
                                                                                tmp_path: Path) -> None:
    out = tmp_path / "run"
    assert train(dataset, out, tiny("mlp", steps=5, checkpoint_every=5), resume=True).start_step == 0
    with pytest.raises(ConfigError, match="lr"):
        train(dataset, out, tiny("mlp", steps=10, checkpoint_every=5, lr=1e-4), resume=True)
    with pytest.raises(ConfigError, match="past --steps 3"):
        train(dataset, out, tiny("mlp", steps=3, checkpoint_every=5), resume=True)


def test_a_second_run_into_the_same_directory_is_refused_without_resume(dataset: Path,
                                                                        tmp_path: Path) -> None:
    out = tmp_path / "run"
    first = train(dataset, out, tiny("mlp", steps=5, checkpoint_every=5)).checkpoint
    before = first.read_bytes()
    with pytest.raises(PolicyError, match="--resume"):
        train(dataset, out, tiny("mlp", steps=5, checkpoint_every=5))
    assert first.read_bytes() == before


def test_resuming_on_another_dataset_is_refused(dataset: Path, tmp_path: Path) -> None:
    other = write_dataset(tmp_path / "other", 3, seed=7)
    out = tmp_path / "run"
    train(dataset, out, tiny("mlp", steps=5, checkpoint_every=5))
    with pytest.raises(CheckpointError, match="another dataset"):
        train(other, out, tiny("mlp", steps=10, checkpoint_every=5), resume=True)


@pytest.mark.parametrize("what", ["loss", "gradient norm"])
def test_a_nan_loss_stops_training_and_keeps_the_last_good_checkpoint(
        dataset: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, what: str) -> None:
    out = tmp_path / "run"
    real = MlpPolicy.loss
    calls = {"n": 0}

    def diverging(self: MlpPolicy, obs: torch.Tensor, action: torch.Tensor,
                  g: torch.Generator, subtask: torch.Tensor | None = None) -> torch.Tensor:
        calls["n"] += 1
        loss = real(self, obs, action, g, subtask)
        if calls["n"] != 13:
            return loss
        if what == "loss":
            return loss * float("nan")
        weight = next(self.parameters()).sum()
        return loss + 0 * torch.sqrt(weight - weight)  # finite value, NaN gradient

    monkeypatch.setattr(MlpPolicy, "loss", diverging)
    with pytest.raises(TrainingDivergedError, match=rf"{what} became nan at step 13.*step-00000010\.pt"):
        train(dataset, out, tiny("mlp", steps=30, checkpoint_every=5))
    kept = checkpoints(out)
    assert [p.name for p in kept] == ["step-00000005.pt", "step-00000010.pt"]
    good = load_checkpoint(kept[-1])
    assert good["step"] == 10 and all(torch.isfinite(v).all() for v in good["model"].values())
    assert not [p for p in (out / "checkpoints").iterdir() if p.name.startswith(".")]  # no temporary files
    monkeypatch.setattr(MlpPolicy, "loss", real)
    assert train(dataset, out, tiny("mlp", steps=30, checkpoint_every=5), resume=True).steps == 30
