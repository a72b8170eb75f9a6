"""DDPM noising and DDIM sampling, checked against the closed-form squared-cosine schedule."""

from __future__ import annotations

import math

import pytest
import torch

from conftest import tiny
from vcage.policy.diffusion import NoiseSchedule
from vcage.policy.models import make_policy


def alpha_bar(t: float, s: float = 0.008) -> float:
    """Nichol & Dhariwal's alpha_bar(t), t in [0, 1], written out independently of the package."""
    return math.cos((t + s) / (1 + s) * math.pi / 2) ** 2 / math.cos(s / (1 + s) * math.pi / 2) ** 2


def test_the_schedule_is_the_squared_cosine_one() -> None:
    schedule = NoiseSchedule(100, 10)
    expected = torch.tensor([alpha_bar((i + 1) / 100) for i in range(100)], dtype=torch.float64)
    # equal except where beta is capped at 0.999 (only the very last step)
    torch.testing.assert_close(schedule.alphas_cumprod[:99], expected[:99], rtol=1e-9, atol=1e-12)
    assert schedule.alphas_cumprod[-1] < 1e-4
    assert schedule.inference_timesteps() == [90, 80, 70, 60, 50, 40, 30, 20, 10, 0]


def test_forward_noising_keeps_shapes_and_unit_variance() -> None:
    schedule = NoiseSchedule(100, 10)
    g = torch.Generator().manual_seed(0)
    x0 = torch.randn(4096, 16, 8, generator=g)
    noise = torch.randn(x0.shape, generator=g)
    for step in (0, 50, 99):
        t = torch.full((x0.shape[0],), step)
        xt = schedule.add_noise(x0, noise, t)
        assert xt.shape == x0.shape
        assert xt.var().item() == pytest.approx(1.0, abs=0.02)  # variance preserving
        ab = schedule.alphas_cumprod[step].item()
        corr = ((xt * x0).mean() / (xt.std() * x0.std())).item()
        assert corr == pytest.approx(math.sqrt(ab), abs=0.02)


@pytest.mark.parametrize("clip", [False, True])
def test_ddim_with_the_true_noise_recovers_the_clean_sample(clip: bool) -> None:
    """With an oracle that returns the exact noise of x_t around a known x0 (from the closed-form
    alpha_bar, not the package's), DDIM must end on x0 itself, from any starting noise."""
    schedule = NoiseSchedule(100, 10, clip_sample=clip)
    g = torch.Generator().manual_seed(1)
    x0 = torch.rand(3, 16, 8, generator=g, dtype=torch.float64) * 1.8 - 0.9
    calls: list[int] = []

    def oracle(x_t: torch.Tensor, t: torch.Tensor) -> torch.Tensor:
        assert t.shape == (3,) and t.dtype == torch.long
        calls.append(int(t[0]))
        ab = alpha_bar((int(t[0]) + 1) / 100)
        return (x_t - math.sqrt(ab) * x0) / math.sqrt(1 - ab)

    start = torch.randn(x0.shape, generator=g, dtype=torch.float64)
    out = schedule.sample(oracle, start)
    assert calls == [90, 80, 70, 60, 50, 40, 30, 20, 10, 0]
    torch.testing.assert_close(out, x0, rtol=0, atol=1e-9)


def test_the_policies_predict_chunks_of_the_horizon() -> None:
    g = torch.Generator().manual_seed(0)
    obs = torch.randn(5, 2, 22, generator=g)
    for kind in ("diffusion", "mlp"):
        policy = make_policy(tiny(kind), 22, 8)
        assert policy.predict(obs, g).shape == (5, 16, 8)
        assert policy.loss(obs, torch.rand(5, 16, 8, generator=g) * 2 - 1, g).dim() == 0
