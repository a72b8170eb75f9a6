"""How a policy reads its observation features: the stored vectors side by side, with every
orientation in a form a network can use (no torch).

Datasets store poses as a position and a unit quaternion ``(w, x, y, z)`` with ``w >= 0``. A
quaternion is a poor network input: ``q`` and ``-q`` are the same rotation, so the stored sign
convention makes the vector jump wherever ``w`` crosses zero, and a gripper pointing straight down
sits exactly there: the end effector's stored quaternion flips between ``(0, 1, 0, 0)`` and
``(0, -1, 0, 0)`` within one demonstration, on the same pose. With ``rotations="rot6d"`` (the
default) every quaternion becomes the first two columns of its rotation matrix (Zhou et al.,
"On the Continuity of Rotation Representations in Neural Networks", 2019): continuous, and the
same for ``q`` and ``-q``. ``"quaternion"`` passes the stored values through (checkpoints written
before this choice existed).

Quaternions are found by their element names: four consecutive elements named ``qw, qx, qy, qz``,
each with the same prefix (``bell.qw`` ... ``bell.qz``) or none.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np

from vcage.errors import ConfigError

ROTATIONS = ("rot6d", "quaternion")
QUATERNION = ("qw", "qx", "qy", "qz")
ROT6D_SIZE = 6


class Feature(Protocol):
    @property
    def name(self) -> str: ...
    @property
    def size(self) -> int: ...
    @property
    def names(self) -> tuple[str, ...] | None: ...


def quaternion_starts(names: Sequence[str] | None) -> list[int]:
    """Indices at which a run of ``qw, qx, qy, qz`` element names (one common prefix) starts."""
    if not names:
        return []
    starts, i = [], 0
    while i + 4 <= len(names):
        run = zip(names[i:i + 4], QUATERNION, strict=True)
        prefixes = {n[:-2] if n.endswith(q) else None for n, q in run}
        prefix = prefixes.pop() if len(prefixes) == 1 else None
        if prefix is not None and (prefix == "" or prefix.endswith(".")):
            starts.append(i)
            i += 4
        else:
            i += 1
    return starts


def rot6d(quat: np.ndarray) -> np.ndarray:
    """(..., 4) quaternions (w, x, y, z), not necessarily unit, -> (..., 6): the rotation matrix's
    first two columns."""
    q = np.asarray(quat, dtype=np.float64)
    q = q / np.maximum(np.linalg.norm(q, axis=-1, keepdims=True), 1e-12)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack([1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y),
                     2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x)], axis=-1)


class ObservationEncoder:
    """Stored observation features (side by side, in order) -> the policy's input vector."""

    def __init__(self, features: Sequence[Feature], rotations: str) -> None:
        if rotations not in ROTATIONS:
            raise ConfigError(f"unknown rotations {rotations!r}; valid: {', '.join(ROTATIONS)}")
        self.rotations = rotations
        self.raw_size = sum(f.size for f in features)
        starts, offset = [], 0
        for f in features:
            if rotations == "rot6d":
                starts += [offset + s for s in quaternion_starts(f.names)]
            offset += f.size
        self.starts = tuple(starts)

    @property
    def size(self) -> int:
        return self.raw_size + len(self.starts) * (ROT6D_SIZE - 4)

    def __call__(self, raw: np.ndarray) -> np.ndarray:
        """(..., raw_size) stored values -> (..., size) float32 inputs."""
        x = np.asarray(raw, dtype=np.float32)
        if x.shape[-1] != self.raw_size:
            raise ValueError(f"expected {self.raw_size} observation values, got {x.shape[-1]}")
        if not self.starts:
            return x
        parts, last = [], 0
        for s in self.starts:
            parts += [x[..., last:s], rot6d(x[..., s:s + 4]).astype(np.float32)]
            last = s + 4
        parts.append(x[..., last:])
        return np.concatenate(parts, axis=-1)
