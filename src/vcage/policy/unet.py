"""The 1D temporal conditional U-Net of Diffusion Policy (Chi et al. 2023), state-based.

The action chunk (batch, horizon, action_dim) is convolved along time. Every residual block is
conditioned by FiLM (a per-channel scale and bias) on one vector: the diffusion step's sinusoidal
embedding (through a small MLP) concatenated with the flattened observation window.
"""

from __future__ import annotations

import math

import torch
from torch import nn


class SinusoidalStepEmbedding(nn.Module):
    def __init__(self, dim: int) -> None:
        super().__init__()
        self.dim = dim

    def forward(self, t: torch.Tensor) -> torch.Tensor:
        half = self.dim // 2
        freqs = torch.exp(torch.arange(half, device=t.device, dtype=torch.float32)
                          * -(math.log(10000.0) / max(half - 1, 1)))
        angles = t.float()[:, None] * freqs[None, :]
        return torch.cat([angles.sin(), angles.cos()], dim=-1)


class ConvBlock(nn.Module):
    """Conv1d, GroupNorm, Mish (same length)."""

    def __init__(self, in_ch: int, out_ch: int, kernel_size: int, n_groups: int) -> None:
        super().__init__()
        self.block = nn.Sequential(nn.Conv1d(in_ch, out_ch, kernel_size, padding=kernel_size // 2),
                                   nn.GroupNorm(n_groups, out_ch), nn.Mish())

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.block(x)


class FilmResidualBlock(nn.Module):
    """Two conv blocks; the condition scales and shifts the channels between them."""

    def __init__(self, in_ch: int, out_ch: int, cond_dim: int, kernel_size: int, n_groups: int) -> None:
        super().__init__()
        self.first = ConvBlock(in_ch, out_ch, kernel_size, n_groups)
        self.second = ConvBlock(out_ch, out_ch, kernel_size, n_groups)
        self.film = nn.Sequential(nn.Mish(), nn.Linear(cond_dim, 2 * out_ch))
        self.residual = nn.Conv1d(in_ch, out_ch, 1) if in_ch != out_ch else nn.Identity()

    def forward(self, x: torch.Tensor, cond: torch.Tensor) -> torch.Tensor:
        out = self.first(x)
        scale, bias = self.film(cond).unsqueeze(-1).chunk(2, dim=1)
        out = self.second(scale * out + bias)
        return out + self.residual(x)


class Level(nn.Module):
    """Two residual blocks at one resolution, then a change of resolution (or none)."""

    def __init__(self, first: FilmResidualBlock, second: FilmResidualBlock, resample: nn.Module) -> None:
        super().__init__()
        self.first, self.second, self.resample = first, second, resample

    def blocks(self, h: torch.Tensor, cond: torch.Tensor) -> torch.Tensor:
        return self.second(self.first(h, cond), cond)


class ConditionalUnet1D(nn.Module):
    """Predicts the noise of a noisy action chunk given the diffusion step and the observations."""

    def __init__(self, action_dim: int, cond_dim: int, down_dims: tuple[int, ...], kernel_size: int,
                 n_groups: int, step_embed_dim: int) -> None:
        super().__init__()
        self.step_encoder = nn.Sequential(SinusoidalStepEmbedding(step_embed_dim),
                                          nn.Linear(step_embed_dim, 4 * step_embed_dim), nn.Mish(),
                                          nn.Linear(4 * step_embed_dim, step_embed_dim))
        cond = step_embed_dim + cond_dim
        dims = [action_dim, *down_dims]
        pairs = list(zip(dims[:-1], dims[1:], strict=True))

        def block(i: int, o: int) -> FilmResidualBlock:
            return FilmResidualBlock(i, o, cond, kernel_size, n_groups)

        self.down = nn.ModuleList([
            Level(block(i, o), block(o, o),
                  nn.Identity() if k == len(pairs) - 1 else nn.Conv1d(o, o, 3, 2, 1))
            for k, (i, o) in enumerate(pairs)])
        self.mid = Level(block(dims[-1], dims[-1]), block(dims[-1], dims[-1]), nn.Identity())
        # back up to the full horizon (the first level's skip is unused, as in Chi et al.'s U-Net)
        self.up = nn.ModuleList([Level(block(2 * o, i), block(i, i), nn.ConvTranspose1d(i, i, 4, 2, 1))
                                 for i, o in reversed(pairs[1:])])
        self.final = nn.Sequential(ConvBlock(down_dims[0], down_dims[0], kernel_size, n_groups),
                                   nn.Conv1d(down_dims[0], action_dim, 1))

    def forward(self, x: torch.Tensor, t: torch.Tensor, obs_cond: torch.Tensor) -> torch.Tensor:
        """``x`` (B, horizon, action_dim), ``t`` (B,) steps, ``obs_cond`` (B, cond_dim) -> noise like x."""
        cond = torch.cat([self.step_encoder(t), obs_cond], dim=-1)
        h = x.transpose(1, 2)
        skips = []
        for level in self.down:
            assert isinstance(level, Level)
            h = level.blocks(h, cond)
            skips.append(h)
            h = level.resample(h)
        h = self.mid.blocks(h, cond)
        for level in self.up:
            assert isinstance(level, Level)
            h = level.resample(level.blocks(torch.cat([h, skips.pop()], dim=1), cond))
        return self.final(h).transpose(1, 2)
