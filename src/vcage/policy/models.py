"""The policies: a state-based diffusion policy and a chunked MLP, behind one small interface.

Both map a normalised observation window (B, n_obs, obs_dim) to a normalised action chunk
(B, horizon, action_dim). ``loss`` is the training objective of one batch; ``predict`` the chunk
at inference. Randomness comes only from the ``generator`` passed in (noise is drawn on the CPU,
so a seed gives the same draws on any device).
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


class Policy(nn.Module):
    """Observation window -> action chunk, both normalised."""

    def __init__(self, config: TrainConfig, obs_dim: int, action_dim: int) -> None:
        super().__init__()
        self.config, self.obs_dim, self.action_dim = config, obs_dim, action_dim

    def loss(self, obs: torch.Tensor, action: torch.Tensor, generator: torch.Generator) -> torch.Tensor:
        return self.loss_from(obs, action, *self.draws(action.shape, generator, action.device))

    def draws(self, shape: torch.Size | tuple[int, ...], generator: torch.Generator,
              device: torch.device) -> tuple[torch.Tensor, ...]:
        """The random inputs of one batch's loss, for an action batch of ``shape``, drawn from the
        (CPU) ``generator`` and put on ``device`` (none by default)."""
        return ()

    def loss_from(self, obs: torch.Tensor, action: torch.Tensor, *draws: torch.Tensor) -> torch.Tensor:
        """The training objective of one batch given its random inputs (:meth:`draws`): what a
        CUDA graph of the training step captures, the draws being copied in before each replay."""
        raise NotImplementedError

    def predict(self, obs: torch.Tensor, generator: torch.Generator) -> torch.Tensor:
        raise NotImplementedError

    def predict_from(self, obs: torch.Tensor, noise: torch.Tensor) -> torch.Tensor:
        """The chunk for ``obs`` starting from the given initial noise (B, horizon, action_dim), so
        that each sample of a batch can draw its noise from its own generator."""
        raise NotImplementedError


POLICIES: Registry[type[Policy]] = Registry("policy", error=ConfigError)


def make_policy(config: TrainConfig, obs_dim: int, action_dim: int) -> Policy:
    return POLICIES.get(config.policy)(config, obs_dim, action_dim)


def randn(shape: tuple[int, ...], generator: torch.Generator, like: torch.Tensor) -> torch.Tensor:
    """Standard normal draws from the (CPU) ``generator``, on the device and dtype of ``like``."""
    return torch.randn(shape, generator=generator).to(device=like.device, dtype=like.dtype)


@POLICIES.register("diffusion")
class DiffusionPolicy(Policy):
    """Diffusion Policy (Chi et al. 2023), state-based: a U-Net denoises the action chunk,
    conditioned on the flattened observation window; epsilon prediction; DDIM at inference."""

    def __init__(self, config: TrainConfig, obs_dim: int, action_dim: int) -> None:
        super().__init__(config, obs_dim, action_dim)
        d = config.diffusion
        self.unet = ConditionalUnet1D(action_dim, obs_dim * config.n_obs_steps, d.down_dims, d.kernel_size,
                                      d.n_groups, d.step_embed_dim)
        self.schedule = NoiseSchedule(d.train_timesteps, d.inference_steps, d.clip_sample)

    def draws(self, shape: torch.Size | tuple[int, ...], generator: torch.Generator,
              device: torch.device) -> tuple[torch.Tensor, ...]:
        """The noise added to the chunk and the diffusion step of each sample."""
        noise = torch.randn(tuple(shape), generator=generator).to(device)
        t = torch.randint(0, self.schedule.train_timesteps, (shape[0],), generator=generator)
        return noise, t.to(device)

    def loss_from(self, obs: torch.Tensor, action: torch.Tensor, *draws: torch.Tensor) -> torch.Tensor:
        noise, t = draws
        noisy = self.schedule.add_noise(action, noise, t)
        return F.mse_loss(self.unet(noisy, t, obs.flatten(1)), noise)

    @torch.no_grad()
    def predict(self, obs: torch.Tensor, generator: torch.Generator) -> torch.Tensor:
        return self.predict_from(obs, randn((obs.shape[0], self.config.horizon, self.action_dim), generator,
                                            obs))

    @torch.no_grad()
    def predict_from(self, obs: torch.Tensor, noise: torch.Tensor) -> torch.Tensor:
        cond = obs.flatten(1)
        return self.schedule.sample(lambda x_t, t: self.unet(x_t, t, cond), noise)


@POLICIES.register("mlp")
class MlpPolicy(Policy):
    """Behaviour cloning: an MLP regresses the whole action chunk from the observation window."""

    def __init__(self, config: TrainConfig, obs_dim: int, action_dim: int) -> None:
        super().__init__(config, obs_dim, action_dim)
        sizes = [obs_dim * config.n_obs_steps, *config.mlp.hidden]
        layers: list[nn.Module] = []
        for i, o in zip(sizes[:-1], sizes[1:], strict=True):
            layers += [nn.Linear(i, o), nn.ReLU()]
        layers.append(nn.Linear(sizes[-1], config.horizon * action_dim))
        self.net = nn.Sequential(*layers)

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        return self.net(obs.flatten(1)).view(obs.shape[0], self.config.horizon, self.action_dim)

    def loss_from(self, obs: torch.Tensor, action: torch.Tensor, *draws: torch.Tensor) -> torch.Tensor:
        return F.mse_loss(self(obs), action)

    @torch.no_grad()
    def predict(self, obs: torch.Tensor, generator: torch.Generator) -> torch.Tensor:
        return self(obs)

    @torch.no_grad()
    def predict_from(self, obs: torch.Tensor, noise: torch.Tensor) -> torch.Tensor:
        return self(obs)
