"""A training step captured as a CUDA graph.

On a GPU, one step of the diffusion U-Net launches thousands of small kernels (convolutions, group
norms, the optimiser's and the EMA's per-tensor updates), so its time is the launches' whatever the
batch: a lent H200 ran one run alone at 20.0 steps per second at batch 256 and 21.4 at 1,024, and
twenty runs sharing it at 3.2-3.6 each (``docs/journal/benchmarks.md``). A CUDA graph records the step's
kernels once and replays them with one launch.

What changes from step to step is copied into fixed device buffers before each replay: the batch's
window indices, the diffusion noise and steps (drawn on the CPU from the run's generator, as in the
eager step, so a seed draws the same numbers), the learning rate and the EMA decay. The first
:data:`WARMUP` steps run eagerly on a side stream, as capture requires (they initialise the
optimiser's state and the libraries' workspaces); they are ordinary training steps.

The loss and gradient norm are read back after the step, so a non-finite value is reported one step
late for the weights in memory: the optimiser has already applied it. Checkpoints written before
are untouched, and the training loop stops without writing another.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import torch

if TYPE_CHECKING:
    from vcage.policy.train import Run

WARMUP = 3  # eager steps on a side stream before the capture


class GraphedStep:
    """Runs :class:`~vcage.policy.train.Run`'s training step from static buffers, as a CUDA graph."""

    def __init__(self, run: Run) -> None:
        if run.device.type != "cuda":
            raise ValueError(f"a CUDA graph needs a CUDA device, not {run.device}")
        self.run = run
        device, batch = run.device, run.config.batch_size
        self.obs_index = run.obs_index.to(device)
        self.action_index = run.action_index.to(device)
        self.rows = torch.zeros(batch, dtype=torch.long, device=device)
        self.shape = (batch, run.action_index.shape[1], run.action.shape[1])  # an action batch's
        self.draws = run.model.draws(self.shape, torch.Generator().manual_seed(0), device)  # shapes only
        self.lr = torch.zeros((), device=device)
        self.decay = torch.zeros((), device=device)
        self.graph: torch.cuda.CUDAGraph | None = None
        self.out: tuple[torch.Tensor, torch.Tensor] | None = None
        self.eager_steps = 0

    def step(self, rows: np.ndarray, draws: tuple[torch.Tensor, ...], lr: float,
             decay: float) -> tuple[float, float]:
        """One training step on window ``rows`` with the loss's random ``draws``: its loss and the
        gradient norm before clipping."""
        run = self.run
        self.rows.copy_(torch.from_numpy(rows), non_blocking=True)
        for buffer, value in zip(self.draws, draws, strict=True):
            buffer.copy_(value, non_blocking=True)
        self.lr.fill_(lr)
        self.decay.fill_(decay)
        for group in run.optimizer.param_groups:
            group["lr"] = self.lr
        if self.graph is None and self.eager_steps < WARMUP:
            side = torch.cuda.Stream(run.device)
            side.wait_stream(torch.cuda.current_stream(run.device))
            with torch.cuda.stream(side):
                run.optimizer.zero_grad(set_to_none=True)
                loss, norm = self._body()
            torch.cuda.current_stream(run.device).wait_stream(side)
            self.eager_steps += 1
        else:
            if self.graph is None:
                self.graph = torch.cuda.CUDAGraph()
                run.optimizer.zero_grad(set_to_none=True)  # the backward's gradients live in the graph's pool
                with torch.cuda.graph(self.graph):
                    self.out = self._body()
            assert self.out is not None
            self.graph.replay()
            loss, norm = self.out
        run.ema.updates += 1
        return float(loss.item()), float(norm.item())

    def _body(self) -> tuple[torch.Tensor, torch.Tensor]:
        run = self.run
        obs, action, subtask = run.gather(self.rows, self.obs_index, self.action_index)
        loss = run.model.loss_from(obs, action, *self.draws, subtask=subtask)
        loss.backward()
        norm = torch.nn.utils.clip_grad_norm_(run.model.parameters(), run.config.grad_clip, foreach=True)
        run.optimizer.step()
        run.ema.average(run.model, self.decay)
        return loss.detach(), norm
