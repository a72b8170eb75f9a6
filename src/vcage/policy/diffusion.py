"""DDPM training noise and DDIM sampling with a squared-cosine schedule (Nichol & Dhariwal 2021).

``alpha_bar(t) = cos((t / T + s) / (1 + s) * pi / 2) ** 2`` with ``s = 0.008``; the betas are
``1 - alpha_bar(t + 1) / alpha_bar(t)`` capped at 0.999, as Diffusion Policy's scheduler makes
them. The model predicts the noise (epsilon). DDIM (Song et al. 2021) with eta = 0 steps
deterministically from pure noise to a sample through ``inference_steps`` of the ``T`` steps,
ending on alpha_bar = 1 (the clean sample).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import torch

COSINE_OFFSET = 0.008
MAX_BETA = 0.999


def cosine_alphas_cumprod(timesteps: int) -> torch.Tensor:
    """alpha_bar of steps 0..T-1 (float64), from the betas of the squared-cosine schedule."""

    def alpha_bar(t: float) -> float:
        return math.cos((t + COSINE_OFFSET) / (1 + COSINE_OFFSET) * math.pi / 2) ** 2

    betas = [min(1 - alpha_bar((i + 1) / timesteps) / alpha_bar(i / timesteps), MAX_BETA)
             for i in range(timesteps)]
    return torch.cumprod(1 - torch.tensor(betas, dtype=torch.float64), dim=0)


class NoiseSchedule:
    """The forward process (:meth:`add_noise`) and the DDIM reverse process (:meth:`sample`)."""

    def __init__(self, train_timesteps: int, inference_steps: int, clip_sample: bool = True) -> None:
        self.train_timesteps = train_timesteps
        self.inference_steps = inference_steps
        self.clip_sample = clip_sample
        self.alphas_cumprod = cosine_alphas_cumprod(train_timesteps)
        self._on: dict[torch.device, torch.Tensor] = {}  # copies on other devices (a CUDA graph copies none)

    def add_noise(self, x0: torch.Tensor, noise: torch.Tensor, t: torch.Tensor) -> torch.Tensor:
        """x_t = sqrt(alpha_bar_t) x0 + sqrt(1 - alpha_bar_t) noise, per sample of the batch."""
        if x0.device not in self._on:
            self._on[x0.device] = self.alphas_cumprod.to(x0.device)
        ab = self._on[x0.device][t].to(x0.dtype).view(-1, *([1] * (x0.dim() - 1)))
        return ab.sqrt() * x0 + (1 - ab).sqrt() * noise

    def inference_timesteps(self) -> list[int]:
        """The DDIM steps, from the noisiest down (evenly spaced, as diffusers' "leading" spacing)."""
        ratio = self.train_timesteps // self.inference_steps
        return [i * ratio for i in reversed(range(self.inference_steps))]

    def ddim_step(self, eps: torch.Tensor, t: int, t_prev: int | None, x_t: torch.Tensor) -> torch.Tensor:
        """x_{t_prev} from x_t and the predicted noise (eta = 0); ``t_prev`` None is the clean end."""
        ab = self.alphas_cumprod[t].item()
        ab_prev = 1.0 if t_prev is None else self.alphas_cumprod[t_prev].item()
        x0 = (x_t - math.sqrt(1 - ab) * eps) / math.sqrt(ab)
        if self.clip_sample:
            x0 = x0.clamp(-1, 1)
            eps = (x_t - math.sqrt(ab) * x0) / math.sqrt(1 - ab)  # the noise consistent with the clip
        return math.sqrt(ab_prev) * x0 + math.sqrt(1 - ab_prev) * eps

    def sample(self, predict_noise: Callable[[torch.Tensor, torch.Tensor], torch.Tensor],
               x_t: torch.Tensor) -> torch.Tensor:
        """Run DDIM from ``x_t`` (pure noise at the first inference step) to a clean sample;
        ``predict_noise(x, t)`` gets ``t`` as a (batch,) long tensor."""
        steps = self.inference_timesteps()
        for i, t in enumerate(steps):
            t_batch = torch.full((x_t.shape[0],), t, dtype=torch.long, device=x_t.device)
            eps = predict_noise(x_t, t_batch)
            x_t = self.ddim_step(eps, t, steps[i + 1] if i + 1 < len(steps) else None, x_t)
        return x_t
