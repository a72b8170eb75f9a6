"""The policies: a state-based diffusion policy and a chunked MLP, behind one small interface.

Both map a normalised observation window (B, n_obs, obs_dim) to a normalised action chunk
(B, horizon, action_dim). ``loss`` is the training objective of one batch; ``predict`` the chunk
at inference. Randomness comes only from the ``generator`` passed in (noise is drawn on the CPU,
so a seed gives the same draws on any device).

A policy of a plan's dataset can be conditioned on the plan's subtask (``subtasks`` > 0): its
action model then reads the subtask as a one-hot vector beside the observation window, and a
classifier head learns to name the subtask from the window (cross-entropy, added to the loss).
Training conditions on the demonstration's subtask; at inference the runner asks the classifier
(:mod:`vcage.policy.inference`). Without it, a state where one subtask has ended looks much like
the one the episode began in (the arm back at its start, the gripper open), and a policy was seen
to do the first subtask again instead of the next (``docs/journal/benchmarks.md``).
"""

from __future__ import annotations

import torch
from torch import nn
from torch.nn import functional as F

from vcage.errors import ConfigError
from vcage.policy.config import TrainConfig
from vcage.policy.diffusion import NoiseSchedule
from vcage.policy.unet import ConditionalUnet1D
from vcage.registry import Registry

SUBTASK_HIDDEN = (256, 256)  # the subtask classifier's hidden layers


def mlp(sizes: list[int]) -> nn.Sequential:
    """Linear layers of the given sizes (input first, output last) with ReLU between them."""
    layers: list[nn.Module] = []
    for i, o in zip(sizes[:-2], sizes[1:-1], strict=True):
        layers += [nn.Linear(i, o), nn.ReLU()]
    return nn.Sequential(*layers, nn.Linear(sizes[-2], sizes[-1]))


def given(subtask: torch.Tensor | None) -> torch.Tensor:
    """The batch's subtasks, which a subtask-conditioned policy cannot do without."""
    if subtask is None:
        raise ValueError("a subtask-conditioned policy needs the subtask of every sample")
    return subtask


class Policy(nn.Module):
    """Observation window -> action chunk, both normalised; with ``subtasks`` > 0, also conditioned
    on the plan's subtask, which :meth:`classify` names from the window."""

    def __init__(self, config: TrainConfig, obs_dim: int, action_dim: int, subtasks: int = 0) -> None:
        super().__init__()
        self.config, self.obs_dim, self.action_dim, self.subtasks = config, obs_dim, action_dim, subtasks
        self.subtask_head = mlp([obs_dim * config.n_obs_steps, *SUBTASK_HIDDEN, subtasks]) \
            if subtasks else None

    @property
    def cond_dim(self) -> int:
        """The size of what the action model is conditioned on: the flattened window and the subtask."""
        return self.obs_dim * self.config.n_obs_steps + self.subtasks

    def condition(self, obs: torch.Tensor, subtask: torch.Tensor | None) -> torch.Tensor:
        """The action model's conditioning: the flattened window, and the subtask as one-hot."""
        flat = obs.flatten(1)
        if not self.subtasks:
            return flat
        return torch.cat([flat, F.one_hot(given(subtask), self.subtasks).to(flat.dtype)], dim=1)

    def classify(self, obs: torch.Tensor) -> torch.Tensor:
        """Logits (B, subtasks) of the subtask each observation window is in."""
        if self.subtask_head is None:
            raise ValueError("this policy is not conditioned on the subtask")
        return self.subtask_head(obs.flatten(1))

    def subtask_loss(self, obs: torch.Tensor, subtask: torch.Tensor | None) -> torch.Tensor | float:
        """The classifier's cross-entropy on the batch's subtasks (0 without a classifier)."""
        if self.subtask_head is None:
            return 0.0
        return F.cross_entropy(self.classify(obs), given(subtask))

    def loss(self, obs: torch.Tensor, action: torch.Tensor, generator: torch.Generator,
             subtask: torch.Tensor | None = None) -> torch.Tensor:
        draws = self.draws(action.shape, generator, action.device)
        return self.loss_from(obs, action, *draws, subtask=subtask)

    def draws(self, shape: torch.Size | tuple[int, ...], generator: torch.Generator,
              device: torch.device) -> tuple[torch.Tensor, ...]:
        """The random inputs of one batch's loss, for an action batch of ``shape``, drawn from the
        (CPU) ``generator`` and put on ``device`` (none by default)."""
        return ()

    def loss_from(self, obs: torch.Tensor, action: torch.Tensor, *draws: torch.Tensor,
                  subtask: torch.Tensor | None = None) -> torch.Tensor:
        """The training objective of one batch given its random inputs (:meth:`draws`): what a
        CUDA graph of the training step captures, the draws being copied in before each replay."""
        raise NotImplementedError

    def predict(self, obs: torch.Tensor, generator: torch.Generator,
                subtask: torch.Tensor | None = None) -> torch.Tensor:
        raise NotImplementedError

    def predict_from(self, obs: torch.Tensor, noise: torch.Tensor,
                     subtask: torch.Tensor | None = None) -> torch.Tensor:
        """The chunk for ``obs`` (in ``subtask``, for a subtask-conditioned policy) starting from the
        given initial noise (B, horizon, action_dim), so that each sample of a batch can draw its
        noise from its own generator."""
        raise NotImplementedError


POLICIES: Registry[type[Policy]] = Registry("policy", error=ConfigError)


def make_policy(config: TrainConfig, obs_dim: int, action_dim: int, subtasks: int = 0) -> Policy:
    return POLICIES.get(config.policy)(config, obs_dim, action_dim, subtasks)


def randn(shape: tuple[int, ...], generator: torch.Generator, like: torch.Tensor) -> torch.Tensor:
    """Standard normal draws from the (CPU) ``generator``, on the device and dtype of ``like``."""
    return torch.randn(shape, generator=generator).to(device=like.device, dtype=like.dtype)


@POLICIES.register("diffusion")
class DiffusionPolicy(Policy):
    """Diffusion Policy (Chi et al. 2023), state-based: a U-Net denoises the action chunk,
    conditioned on the flattened observation window; epsilon prediction; DDIM at inference."""

    def __init__(self, config: TrainConfig, obs_dim: int, action_dim: int, subtasks: int = 0) -> None:
        super().__init__(config, obs_dim, action_dim, subtasks)
        d = config.diffusion
        self.unet = ConditionalUnet1D(action_dim, self.cond_dim, d.down_dims, d.kernel_size, d.n_groups,
                                      d.step_embed_dim)
        self.schedule = NoiseSchedule(d.train_timesteps, d.inference_steps, d.clip_sample)

    def draws(self, shape: torch.Size | tuple[int, ...], generator: torch.Generator,
              device: torch.device) -> tuple[torch.Tensor, ...]:
        """The noise added to the chunk and the diffusion step of each sample."""
        noise = torch.randn(tuple(shape), generator=generator).to(device)
        t = torch.randint(0, self.schedule.train_timesteps, (shape[0],), generator=generator)
        return noise, t.to(device)

    def loss_from(self, obs: torch.Tensor, action: torch.Tensor, *draws: torch.Tensor,
                  subtask: torch.Tensor | None = None) -> torch.Tensor:
        noise, t = draws
        noisy = self.schedule.add_noise(action, noise, t)
        return F.mse_loss(self.unet(noisy, t, self.condition(obs, subtask)), noise) \
            + self.subtask_loss(obs, subtask)

    @torch.no_grad()
    def predict(self, obs: torch.Tensor, generator: torch.Generator,
                subtask: torch.Tensor | None = None) -> torch.Tensor:
        return self.predict_from(obs, randn((obs.shape[0], self.config.horizon, self.action_dim), generator,
                                            obs), subtask)

    @torch.no_grad()
    def predict_from(self, obs: torch.Tensor, noise: torch.Tensor,
                     subtask: torch.Tensor | None = None) -> torch.Tensor:
        cond = self.condition(obs, subtask)
        return self.schedule.sample(lambda x_t, t: self.unet(x_t, t, cond), noise)


@POLICIES.register("mlp")
class MlpPolicy(Policy):
    """Behaviour cloning: an MLP regresses the whole action chunk from the observation window."""

    def __init__(self, config: TrainConfig, obs_dim: int, action_dim: int, subtasks: int = 0) -> None:
        super().__init__(config, obs_dim, action_dim, subtasks)
        self.net = mlp([self.cond_dim, *config.mlp.hidden, config.horizon * action_dim])

    def forward(self, obs: torch.Tensor, subtask: torch.Tensor | None = None) -> torch.Tensor:
        return self.net(self.condition(obs, subtask)).view(obs.shape[0], self.config.horizon, self.action_dim)

    def loss_from(self, obs: torch.Tensor, action: torch.Tensor, *draws: torch.Tensor,
                  subtask: torch.Tensor | None = None) -> torch.Tensor:
        return F.mse_loss(self(obs, subtask), action) + self.subtask_loss(obs, subtask)

    @torch.no_grad()
    def predict(self, obs: torch.Tensor, generator: torch.Generator,
                subtask: torch.Tensor | None = None) -> torch.Tensor:
        return self(obs, subtask)

    @torch.no_grad()
    def predict_from(self, obs: torch.Tensor, noise: torch.Tensor,
                     subtask: torch.Tensor | None = None) -> torch.Tensor:
        return self(obs, subtask)
