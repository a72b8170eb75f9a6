"""The pieces of the CUDA-graphed training step that run without a GPU.

The graph itself needs CUDA, which CI has not: `benchmarks/train_step_gpu.py` measures it on a GPU
(steps per second, and how far its weights drift from the eager step's; `docs/journal/benchmarks.md`). What
it relies on is checked here: the loss's random inputs drawn apart from the loss give the same loss
as before, the EMA's in-memory decay averages as the numeric one does, checkpoints store learning
rates as numbers, and asking for a graph without CUDA is refused before anything is written.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import torch

from conftest import tiny
from vcage.errors import ConfigError
from vcage.policy.config import DiffusionConfig
from vcage.policy.ema import Ema
from vcage.policy.models import make_policy
from vcage.policy.train import _plain_lr, train

SMALL = DiffusionConfig(down_dims=(16, 32), n_groups=4, step_embed_dim=16, kernel_size=3, inference_steps=5)


@pytest.mark.parametrize("policy", ["diffusion", "mlp"])
def test_the_loss_from_separate_draws_is_the_loss(policy: str) -> None:
    """A graph replays the loss from draws copied in: drawing them apart must consume the generator
    as the loss did, so a seed trains the same numbers either way."""
    config = tiny(policy, diffusion=SMALL)
    model = make_policy(config, 5, 4).eval()
    gen = torch.Generator().manual_seed(3)
    obs, action = torch.randn(6, 2, 5, generator=gen), torch.rand(6, 16, 4, generator=gen) * 2 - 1
    with torch.no_grad():
        whole = model.loss(obs, action, torch.Generator().manual_seed(9))
        draws = model.draws(action.shape, torch.Generator().manual_seed(9), torch.device("cpu"))
        apart = model.loss_from(obs, action, *draws)
        other = model.loss_from(obs, action, *model.draws(action.shape, torch.Generator().manual_seed(10),
                                                          torch.device("cpu")))
    assert torch.equal(whole, apart)
    assert len(draws) == (2 if policy == "diffusion" else 0)
    if policy == "diffusion":  # the draws matter: other noise, another loss
        assert not torch.equal(whole, other)


def test_the_ema_averages_alike_with_a_decay_held_in_a_tensor() -> None:
    torch.manual_seed(0)
    model = torch.nn.Sequential(torch.nn.Linear(4, 3), torch.nn.Linear(3, 2))
    by_number, by_tensor = Ema(model, 0.75, 0.9999), Ema(model, 0.75, 0.9999)
    for _ in range(5):
        with torch.no_grad():
            for p in model.parameters():
                p.add_(torch.randn_like(p))
        decay = by_tensor.decay()
        by_number.update(model)
        by_tensor.average(model, torch.tensor(decay))
        by_tensor.updates += 1
    assert by_number.updates == by_tensor.updates == 5
    for a, b in zip(by_number.model.parameters(), by_tensor.model.parameters(), strict=True):
        torch.testing.assert_close(a, b, rtol=1e-6, atol=1e-6)
    moved = Ema(model, 0.75, 0.9999)
    before = [p.detach().clone() for p in model.parameters()]
    with torch.no_grad():
        for p in model.parameters():
            p.add_(1.0)
    moved.average(model, torch.tensor(0.25))  # the tensor is the decay: a quarter of the old weights
    for kept, old, new in zip(moved.model.parameters(), before, model.parameters(), strict=True):
        torch.testing.assert_close(kept, 0.25 * old + 0.75 * new)


def test_a_checkpoint_stores_learning_rates_as_numbers() -> None:
    """In a graph the learning rate lives in a device tensor; a checkpoint must not carry it."""
    optimizer = torch.optim.AdamW([torch.nn.Parameter(torch.zeros(3))], lr=1e-3)
    optimizer.param_groups[0]["lr"] = torch.tensor(2.5e-4)
    state = _plain_lr(optimizer.state_dict())
    lr = state["param_groups"][0]["lr"]
    assert isinstance(lr, float) and lr == pytest.approx(2.5e-4)
    assert isinstance(optimizer.param_groups[0]["lr"], torch.Tensor)  # the optimiser keeps its own


def test_a_graph_without_cuda_is_refused_before_anything_is_written(dataset: Path, tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="CUDA graph .* needs a CUDA device"):
        train(dataset, tmp_path / "run", tiny("mlp", steps=3, checkpoint_every=1), graph=True)
    assert not (tmp_path / "run" / "checkpoints").exists()
