"""Policy learning on vcage datasets (the optional ``policy`` extra; the only importer of torch).

Modules, one concept each: :mod:`~vcage.policy.config` (the run's configuration),
:mod:`~vcage.policy.dataset` (frames read through ``DatasetReader``), :mod:`~vcage.policy.windows`
(``delta_timestamps``-style windows), :mod:`~vcage.policy.normalize`, :mod:`~vcage.policy.sampler`,
:mod:`~vcage.policy.diffusion` (DDPM/DDIM), :mod:`~vcage.policy.unet`, :mod:`~vcage.policy.models`
(diffusion and MLP policies), :mod:`~vcage.policy.ema`, :mod:`~vcage.policy.checkpoint`,
:mod:`~vcage.policy.train`, :mod:`~vcage.policy.inference`, :mod:`~vcage.policy.ensemble`,
:mod:`~vcage.policy.rollout`, :mod:`~vcage.policy.evaluate`, :mod:`~vcage.policy.metrics`,
:mod:`~vcage.policy.errors`.

Importing this package does not import torch; the modules that need it do (``train``,
``evaluate``, ``models`` ...), so ``vcage --help`` starts without it.
"""

from vcage.policy.config import DiffusionConfig, MlpConfig, TrainConfig
from vcage.policy.errors import (
    CheckpointError,
    EnvironmentMismatchError,
    MissingFeatureError,
    PolicyError,
    TrainingDivergedError,
)

__all__ = ["CheckpointError", "DiffusionConfig", "EnvironmentMismatchError", "MissingFeatureError",
           "MlpConfig", "PolicyError", "TrainConfig", "TrainingDivergedError"]
