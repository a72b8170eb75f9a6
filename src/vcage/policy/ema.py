"""An exponential moving average of a model's weights (Diffusion Policy's EMA schedule)."""

from __future__ import annotations

import copy

import torch
from torch import nn


class Ema:
    """Keeps ``model``'s averaged copy: decay ``1 - (1 + step) ** -power``, capped at ``max_decay``
    (so early steps follow the weights closely and later ones average over more steps)."""

    def __init__(self, model: nn.Module, power: float, max_decay: float) -> None:
        self.model = copy.deepcopy(model).eval().requires_grad_(False)
        self.power, self.max_decay = power, max_decay
        self.updates = 0

    def decay(self) -> float:
        return min(self.max_decay, max(0.0, 1 - (1 + self.updates) ** -self.power))

    def update(self, model: nn.Module) -> None:
        """Average ``model``'s weights in with :meth:`decay`, and count the update."""
        self.average(model)
        self.updates += 1

    @torch.no_grad()
    def average(self, model: nn.Module, decay: torch.Tensor | None = None) -> None:
        """Average ``model``'s weights in, without counting. ``decay``, a 0-d tensor on the model's
        device, replaces :meth:`decay` inside a CUDA graph (which replays kernels, so the number must
        live in memory the host refills before each replay); the caller keeps it equal to
        :meth:`decay` and counts the update."""
        averaged: list[torch.Tensor] = list(self.model.parameters())
        current: list[torch.Tensor] = [p.detach() for p in model.parameters()]
        if len(averaged) != len(current):
            raise ValueError(f"the EMA holds {len(averaged)} parameters, the model {len(current)}")
        # one kernel per operation for all parameters (on a GPU, a loop launches two per parameter)
        if decay is None:
            value = self.decay()
            torch._foreach_mul_(averaged, value)
            torch._foreach_add_(averaged, current, alpha=1 - value)
        else:
            torch._foreach_mul_(averaged, decay)
            torch._foreach_add_(averaged, torch._foreach_mul(current, 1 - decay))
        for kept, buffer in zip(self.model.buffers(), model.buffers(), strict=True):
            kept.copy_(buffer)

    def state_dict(self) -> dict[str, object]:
        return {"model": self.model.state_dict(), "updates": self.updates}

    def load_state_dict(self, state: dict[str, object]) -> None:
        self.model.load_state_dict(state["model"])  # type: ignore[arg-type]
        self.updates = int(state["updates"])  # type: ignore[call-overload]
