"""Normalisation of observations and actions from a dataset's frames (no torch).

Actions go to [-1, 1] by their min and max (the range the diffusion sampler clips to);
observations by min/max the same way, or to zero mean and unit standard deviation. A dimension
whose range (or standard deviation) is below ``EPS`` is only centred, so a constant feature
(e.g. an object's quaternion that never changes) maps to 0 instead of dividing by zero.

A ``floor`` (per dimension, in the feature's own units) keeps the scale from falling below a
physical size: without it a dimension that barely moves in clean demonstrations (a pad's tilt
spanning 1.5e-4) is stretched to [-1, 1], and a deviation of a milliradian in closed loop becomes an
input of several units, far outside anything the network was trained on.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from vcage.errors import ConfigError

EPS = 1e-6


@dataclass(frozen=True)
class Normalizer:
    """``(x - center) / scale`` per dimension, and back."""

    center: np.ndarray
    scale: np.ndarray

    @classmethod
    def fit(cls, frames: np.ndarray, mode: str, floor: np.ndarray | float = 0.0) -> Normalizer:
        """From (T, n) frames: ``min_max`` (to [-1, 1]) or ``mean_std``; no scale below ``floor``."""
        x = np.asarray(frames, dtype=np.float64)
        if x.ndim != 2 or len(x) == 0:
            raise ConfigError(f"normalisation needs (T, n) frames with T >= 1, got shape {x.shape}")
        if mode == "min_max":
            low, high = x.min(axis=0), x.max(axis=0)
            center, scale = (high + low) / 2, (high - low) / 2
        elif mode == "mean_std":
            center, scale = x.mean(axis=0), x.std(axis=0)
        else:
            raise ConfigError(f"unknown normalisation {mode!r}; valid: min_max, mean_std")
        floor = np.broadcast_to(np.asarray(floor, dtype=np.float64), scale.shape)
        if np.any(floor < 0) or not np.all(np.isfinite(floor)):
            raise ConfigError("a normalisation floor must be a finite number >= 0")
        scale = np.where((scale < EPS) & (floor <= 0), 1.0, np.maximum(scale, floor))
        return cls(center, scale)

    def normalize(self, x: np.ndarray) -> np.ndarray:
        return ((np.asarray(x, dtype=np.float64) - self.center) / self.scale).astype(np.float32)

    def unnormalize(self, x: np.ndarray) -> np.ndarray:
        return (np.asarray(x, dtype=np.float64) * self.scale + self.center).astype(np.float32)

    def to_dict(self) -> dict[str, Any]:
        return {"center": self.center.tolist(), "scale": self.scale.tolist()}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Normalizer:
        return cls(np.asarray(data["center"], dtype=np.float64), np.asarray(data["scale"], dtype=np.float64))
