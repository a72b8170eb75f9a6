"""How a policy reads its observation features and writes its action: the stored vectors side by
side, with every orientation in a form a network can use (no torch).

Datasets store poses as a position and a unit quaternion ``(w, x, y, z)`` with ``w >= 0``. A
quaternion is a poor network input: ``q`` and ``-q`` are the same rotation, so the stored sign
convention makes the vector jump wherever ``w`` crosses zero, and a gripper pointing straight down
sits exactly there: the end effector's stored quaternion flips between ``(0, 1, 0, 0)`` and
``(0, -1, 0, 0)`` within one demonstration, on the same pose. With ``rotations="rot6d"`` (the
default) every quaternion becomes the first two columns of its rotation matrix (Zhou et al.,
"On the Continuity of Rotation Representations in Neural Networks", 2019): continuous, and the
same for ``q`` and ``-q``. ``"quaternion"`` passes the stored values through (checkpoints written
before this choice existed).

An action feature with a quaternion (``action.ee_pose``) is encoded the same way for training, and
the network's output is decoded back (:meth:`VectorEncoder.decode`: the two columns made orthonormal
by Gram-Schmidt, the third their cross product, then the quaternion with ``w >= 0``).

Quaternions are found by their element names: four consecutive elements named ``qw, qx, qy, qz``,
each with the same prefix (``bell.qw`` ... ``bell.qz``) or none.

With ``relative=True`` an observation encoder also appends, for every object position it reads
(three consecutive elements ``P.x, P.y, P.z``), that position minus the tool's (the elements ``x, y,
z`` with no prefix, the end effector's pose): the offset from the hand to each object, which a
network otherwise has to learn to subtract from two absolute inputs (positions in the world frame,
in metres).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np

from vcage.errors import ConfigError
from vcage.geometry import mat_to_quat

ROTATIONS = ("rot6d", "quaternion")
QUATERNION = ("qw", "qx", "qy", "qz")
POSITION = ("x", "y", "z")
ROT6D_SIZE = 6


class Feature(Protocol):
    @property
    def name(self) -> str: ...
    @property
    def size(self) -> int: ...
    @property
    def names(self) -> tuple[str, ...] | None: ...


def named_runs(names: Sequence[str] | None, suffixes: Sequence[str]) -> list[tuple[str, int]]:
    """(prefix, index) of each run of element names ending in ``suffixes`` in order with one common
    prefix (``""`` for none, else an object's name and a dot: ``bell.``), runs not overlapping."""
    if not names:
        return []
    found, i, n = [], 0, len(suffixes)
    while i + n <= len(names):
        run = zip(names[i:i + n], suffixes, strict=True)
        prefixes = {name[:-len(suffix)] if name.endswith(suffix) else None for name, suffix in run}
        prefix = prefixes.pop() if len(prefixes) == 1 else None
        if prefix is not None and (prefix == "" or prefix.endswith(".")):
            found.append((prefix, i))
            i += n
        else:
            i += 1
    return found


def quaternion_starts(names: Sequence[str] | None) -> list[int]:
    """Indices at which a run of ``qw, qx, qy, qz`` element names (one common prefix) starts."""
    return [i for _, i in named_runs(names, QUATERNION)]


def position_starts(names: Sequence[str] | None) -> list[tuple[str, int]]:
    """(prefix, index) of each run of ``x, y, z`` element names with one common prefix (``""`` for
    none, else ending in a dot: ``mouse.``)."""
    return named_runs(names, POSITION)


def rot6d(quat: np.ndarray) -> np.ndarray:
    """(..., 4) quaternions (w, x, y, z), not necessarily unit, -> (..., 6): the rotation matrix's
    first two columns."""
    q = np.asarray(quat, dtype=np.float64)
    q = q / np.maximum(np.linalg.norm(q, axis=-1, keepdims=True), 1e-12)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack([1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y),
                     2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x)], axis=-1)


def rot6d_to_quat(x: np.ndarray) -> np.ndarray:
    """(..., 6) two rotation-matrix columns, not necessarily orthonormal -> (..., 4) unit quaternions
    (w, x, y, z) with ``w >= 0`` of the nearest rotation (Gram-Schmidt)."""
    x = np.asarray(x, dtype=np.float64)
    a, b = x[..., :3], x[..., 3:6]
    c1 = a / np.maximum(np.linalg.norm(a, axis=-1, keepdims=True), 1e-12)
    b = b - np.sum(c1 * b, axis=-1, keepdims=True) * c1
    c2 = b / np.maximum(np.linalg.norm(b, axis=-1, keepdims=True), 1e-12)
    c3 = np.cross(c1, c2)
    flat = np.stack([c1, c2, c3], axis=-1).reshape(-1, 3, 3)  # the columns side by side
    return np.array([mat_to_quat(m) for m in flat]).reshape(*x.shape[:-1], 4)


class VectorEncoder:
    """Stored vector features (side by side, in order) -> the policy's vector (observation input or
    action output), and back for actions (:meth:`decode`); ``relative``: append the tool-to-object
    offsets (observations only)."""

    def __init__(self, features: Sequence[Feature], rotations: str, relative: bool = False) -> None:
        if rotations not in ROTATIONS:
            raise ConfigError(f"unknown rotations {rotations!r}; valid: {', '.join(ROTATIONS)}")
        self.rotations = rotations
        self.raw_size = sum(f.size for f in features)
        starts, offset = [], 0
        tools: list[int] = []
        objects: list[int] = []
        for f in features:
            if rotations == "rot6d":
                starts += [offset + s for s in quaternion_starts(f.names)]
            for prefix, at in position_starts(f.names):
                (tools if prefix == "" else objects).append(offset + at)
            offset += f.size
        self.starts = tuple(starts)
        self.relative = bool(relative)
        self.tool: int | None = None
        self.objects: tuple[int, ...] = ()
        if self.relative:
            if len(tools) != 1 or not objects:
                raise ConfigError(
                    "object-relative inputs need the tool's position (one run of elements x, y, z: "
                    "observation.ee_pose) and at least one object's (P.x, P.y, P.z: "
                    f"observation.environment_state) among the observed features; found {len(tools)} "
                    f"tool and {len(objects)} object positions: observe both, or train without them")
            self.tool, self.objects = tools[0], tuple(objects)

    @property
    def size(self) -> int:
        return self.raw_size + len(self.starts) * (ROT6D_SIZE - 4) + 3 * len(self.objects)

    def rotation_mask(self) -> np.ndarray:
        """(size,) bool: which values of the encoded vector are rotation-matrix columns (or, with
        ``rotations="quaternion"``, none: a quaternion passes through as four plain values)."""
        mask, shift = np.zeros(self.size, dtype=bool), 0  # offsets (at the end) are positions
        for s in self.starts:
            mask[s + shift:s + shift + ROT6D_SIZE] = True
            shift += ROT6D_SIZE - 4
        return mask

    def __call__(self, raw: np.ndarray) -> np.ndarray:
        """(..., raw_size) stored values -> (..., size) float32 inputs."""
        x = np.asarray(raw, dtype=np.float32)
        if x.shape[-1] != self.raw_size:
            raise ValueError(f"expected {self.raw_size} values, got {x.shape[-1]}")
        parts, last = [], 0
        for s in self.starts:
            parts += [x[..., last:s], rot6d(x[..., s:s + 4]).astype(np.float32)]
            last = s + 4
        parts.append(x[..., last:])
        if self.tool is not None:
            tool = x[..., self.tool:self.tool + 3]
            parts += [x[..., o:o + 3] - tool for o in self.objects]
        return np.concatenate(parts, axis=-1) if len(parts) > 1 else x

    def decode(self, encoded: np.ndarray) -> np.ndarray:
        """(..., size) policy values -> (..., raw_size) values in the stored form (each rot6d pair of
        columns back to a unit quaternion)."""
        x = np.asarray(encoded, dtype=np.float32)
        if self.relative:
            raise ValueError("an encoder with object-relative inputs encodes observations: it decodes "
                             "nothing")
        if x.shape[-1] != self.size:
            raise ValueError(f"expected {self.size} encoded values, got {x.shape[-1]}")
        if not self.starts:
            return x
        parts, last, shift = [], 0, 0
        for s in self.starts:
            at = s + shift  # where this quaternion's 6 values begin in the encoded vector
            parts += [x[..., last:at], rot6d_to_quat(x[..., at:at + ROT6D_SIZE]).astype(np.float32)]
            last = at + ROT6D_SIZE
            shift += ROT6D_SIZE - 4
        parts.append(x[..., last:])
        return np.concatenate(parts, axis=-1)
