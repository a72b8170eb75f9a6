"""The configuration of a training run, as frozen data (no torch): stored in every checkpoint.

Defaults are sized for a CPU: the diffusion U-Net has about 1.2 M parameters and the MLP about
0.35 M (with the 26 input values of a one-object dataset); the diffusion policy trains its default
15,000 steps in about 20 minutes on one core, the MLP in under two. The window sizes follow
Diffusion Policy (and LeRobot's ``delta_timestamps`` for it): 2 observation frames (previous and
current), a 16-step action chunk starting at the previous frame, of which 8 are executed from the
current frame on.
"""

from __future__ import annotations

import math
import re
from dataclasses import asdict, dataclass, field
from typing import Any

from vcage.config import from_fields
from vcage.errors import ConfigError
from vcage.policy.encoding import ROTATIONS

POLICY_KINDS = ("diffusion", "mlp")
OBS_NORMS = ("min_max", "mean_std")
# The observation features used when none are named: those of the list the dataset has.
DEFAULT_OBSERVATIONS = ("observation.state", "observation.ee_pose", "observation.environment_state")
REQUIRED_OBSERVATIONS = ("observation.state", "observation.ee_pose")
ACTION = "action"
# What a policy can predict: the joint targets (``action``) or the tool's target pose and the gripper
# (``action.ee_pose``, which the evaluation environment turns into joint targets by IK); the same as
# vcage.pipeline.features.ACTIONS, which this module cannot import (training loads no simulator).
ACTIONS = (ACTION, "action.ee_pose")
# The per-frame subtask of a plan's episode (vcage.pipeline.features.SUBTASK), which a
# subtask-conditioned policy learns to recognise
SUBTASK = "subtask_index"
# An observation key: a feature's name, or its name and some of its elements by name in brackets
# (``observation.state[gripper_width]``), which the policy then observes alone, in the order given
_KEY = re.compile(r"([^\[\],\s]+)(?:\[([^\[\]]+)\])?")


def split_key(key: str) -> tuple[str, tuple[str, ...] | None]:
    """The feature an observation key reads and the elements it selects (None: all of them)."""
    match = _KEY.fullmatch(str(key).strip())
    if match is None:
        raise ConfigError(f"observation key {key!r} is neither a feature name nor FEATURE[ELEMENT,...] "
                          "(e.g. observation.state[gripper_width])")
    if match.group(2) is None:
        return match.group(1), None
    elements = tuple(e.strip() for e in match.group(2).split(","))
    if not all(elements) or len(set(elements)) != len(elements):
        raise ConfigError(f"observation key {key!r} must name distinct elements between its brackets")
    return match.group(1), elements


def split_keys(text: str) -> tuple[str, ...]:
    """Comma-separated observation keys (a comma between brackets separates elements, not keys)."""
    return tuple(k.strip() for k in re.split(r",(?![^\[]*\])", text) if k.strip())


def _positive(owner: str, **values: float) -> None:
    for name, value in values.items():
        if isinstance(value, bool) or not isinstance(value, int | float) or not value > 0 \
                or not math.isfinite(value):
            raise ConfigError(f"{owner}.{name} must be a positive number, got {value!r}")


@dataclass(frozen=True)
class DiffusionConfig:
    """The diffusion policy: a 1D temporal U-Net (Chi et al. 2023), DDPM training, DDIM sampling."""

    down_dims: tuple[int, ...] = (32, 64, 128)  # channels of the U-Net's levels (16 -> 8 -> 4 steps)
    kernel_size: int = 5
    n_groups: int = 8  # GroupNorm groups; every entry of down_dims must be divisible by it
    step_embed_dim: int = 64  # sinusoidal embedding of the diffusion step
    train_timesteps: int = 100  # DDPM steps, squared-cosine noise schedule
    inference_steps: int = 10  # DDIM steps at inference
    clip_sample: bool = True  # clip the predicted clean chunk to the normalised range [-1, 1]

    def __post_init__(self) -> None:
        object.__setattr__(self, "down_dims", tuple(int(d) for d in self.down_dims))
        if not self.down_dims:
            raise ConfigError("diffusion.down_dims needs at least one level, e.g. (64, 128, 256)")
        _positive("diffusion", kernel_size=self.kernel_size, n_groups=self.n_groups,
                  step_embed_dim=self.step_embed_dim, train_timesteps=self.train_timesteps,
                  inference_steps=self.inference_steps, **{f"down_dims[{i}]": d
                                                            for i, d in enumerate(self.down_dims)})
        if any(d % self.n_groups for d in self.down_dims):
            raise ConfigError(f"diffusion.down_dims {self.down_dims} must all be divisible by n_groups "
                              f"{self.n_groups}")
        if self.kernel_size % 2 == 0:
            raise ConfigError(f"diffusion.kernel_size must be odd (same-length convolutions), got "
                              f"{self.kernel_size}")
        if self.inference_steps > self.train_timesteps:
            raise ConfigError(f"diffusion.inference_steps ({self.inference_steps}) cannot exceed "
                              f"train_timesteps ({self.train_timesteps})")
        if self.step_embed_dim % 2:
            raise ConfigError(f"diffusion.step_embed_dim must be even, got {self.step_embed_dim}")


@dataclass(frozen=True)
class MlpConfig:
    """The behaviour-cloning baseline: an MLP from the observation window to the action chunk."""

    hidden: tuple[int, ...] = (512, 512)

    def __post_init__(self) -> None:
        object.__setattr__(self, "hidden", tuple(int(h) for h in self.hidden))
        _positive("mlp", **{f"hidden[{i}]": h for i, h in enumerate(self.hidden)})


@dataclass(frozen=True)
class TrainConfig:
    """One training run: the policy, its sizes, the optimisation and the observation features."""

    policy: str = "diffusion"
    steps: int = 15000  # 3,000 left a press-the-bell policy at 10% (docs/journal/benchmarks.md)
    batch_size: int = 64
    lr: float = 1e-3  # AdamW, linear warm-up then cosine decay to 0
    weight_decay: float = 1e-6
    warmup_steps: int = 100
    grad_clip: float = 10.0  # max gradient norm
    seed: int = 0
    checkpoint_every: int = 1000  # each holds weights, EMA and optimiser: about 20 MB at the default sizes
    observation_keys: tuple[str, ...] | None = None  # None: DEFAULT_OBSERVATIONS the dataset has
    action_key: str = ACTION  # one of ACTIONS
    obs_norm: str = "min_max"  # observations to [-1, 1] (min_max) or to zero mean, unit std (mean_std)
    # the smallest normalisation scale of a value (observations and actions), in its own units: rotation-
    # matrix columns ``rotation_floor``, every other value (positions in m, joints in rad, widths)
    # ``norm_floor``; 0 turns a floor off (a value that never moves is then only centred)
    norm_floor: float = 0.01
    rotation_floor: float = 0.05
    rotations: str = "rot6d"  # quaternions read as rotation-matrix columns (see vcage.policy.encoding)
    # append each observed object's position minus the tool's (vcage.policy.encoding): needs
    # observation.ee_pose and observation.environment_state among the observations
    relative_objects: bool = False
    n_obs_steps: int = 2
    # frames between two observed frames: the window reaches (n_obs_steps - 1) * obs_stride frames back,
    # so a few frames can span a whole motion (the way down to a button and the way back up look
    # alike over 2 frames; docs/journal/benchmarks.md)
    obs_stride: int = 1
    horizon: int = 16
    n_action_steps: int = 8
    ema_power: float = 0.75  # EMA decay 1 - (1 + step) ** -power, at most ema_max_decay
    ema_max_decay: float = 0.9999
    # Hierarchical: a classifier head names the plan's subtask from the observation window and the
    # action model is conditioned on it (training: on the demonstration's subtask_index; inference:
    # on the classifier's answer, which never goes back to an earlier subtask within an episode)
    subtask_conditioned: bool = False
    diffusion: DiffusionConfig = field(default_factory=DiffusionConfig)
    mlp: MlpConfig = field(default_factory=MlpConfig)

    def __post_init__(self) -> None:
        if self.policy not in POLICY_KINDS:
            raise ConfigError(f"unknown policy {self.policy!r}; valid: {', '.join(POLICY_KINDS)}")
        if self.obs_norm not in OBS_NORMS:
            raise ConfigError(f"unknown obs_norm {self.obs_norm!r}; valid: {', '.join(OBS_NORMS)}")
        if self.action_key not in ACTIONS:
            raise ConfigError(f"unknown action {self.action_key!r}; valid: {', '.join(ACTIONS)}")
        if self.rotations not in ROTATIONS:
            raise ConfigError(f"unknown rotations {self.rotations!r}; valid: {', '.join(ROTATIONS)}")
        for name in ("steps", "batch_size", "checkpoint_every", "n_obs_steps", "obs_stride", "horizon",
                     "n_action_steps"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise ConfigError(f"{name} must be a positive integer, got {value!r}")
        if not isinstance(self.relative_objects, bool):
            raise ConfigError(f"relative_objects must be true or false, got {self.relative_objects!r}")
        if not isinstance(self.subtask_conditioned, bool):
            raise ConfigError(f"subtask_conditioned must be true or false, got {self.subtask_conditioned!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise ConfigError(f"seed must be a non-negative integer, got {self.seed!r}")
        if isinstance(self.warmup_steps, bool) or not isinstance(self.warmup_steps, int) \
                or self.warmup_steps < 0:
            raise ConfigError(f"warmup_steps must be a non-negative integer, got {self.warmup_steps!r}")
        _positive("train", lr=self.lr, grad_clip=self.grad_clip, ema_power=self.ema_power)
        for name in ("norm_floor", "rotation_floor"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float) or not 0 <= value < 1:
                raise ConfigError(f"{name} must be a number in [0, 1), got {value!r}")
        if not 0 <= self.weight_decay < 1:
            raise ConfigError(f"weight_decay must be in [0, 1), got {self.weight_decay}")
        if not 0 <= self.ema_max_decay < 1:
            raise ConfigError(f"ema_max_decay must be in [0, 1), got {self.ema_max_decay}")
        if self.n_obs_steps - 1 + self.n_action_steps > self.horizon:
            raise ConfigError(f"the executed actions (n_action_steps {self.n_action_steps}, from the "
                              f"current frame, which is step {self.n_obs_steps - 1} of the chunk) must "
                              f"fit in the horizon {self.horizon}")
        if self.policy == "diffusion" and self.horizon % 2 ** (len(self.diffusion.down_dims) - 1):
            raise ConfigError(f"horizon {self.horizon} must be divisible by 2 ** (levels - 1) = "
                              f"{2 ** (len(self.diffusion.down_dims) - 1)} for the U-Net's down-sampling")
        if self.observation_keys is not None:
            keys = tuple(str(k).strip() for k in self.observation_keys)
            reserved = {*ACTIONS, SUBTASK}
            if not keys or len(set(keys)) != len(keys) or {split_key(k)[0] for k in keys} & reserved:
                raise ConfigError(f"observation_keys must be distinct feature names (or "
                                  f"FEATURE[ELEMENT,...]) other than the actions {', '.join(ACTIONS)} and "
                                  f"{SUBTASK} (which subtask_conditioned uses), got "
                                  f"{self.observation_keys!r}")
            object.__setattr__(self, "observation_keys", keys)

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: Any) -> TrainConfig:
        return from_fields(cls, data, diffusion=DiffusionConfig, mlp=MlpConfig)
