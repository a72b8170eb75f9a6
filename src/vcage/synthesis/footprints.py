"""Batched planar geometry of resting footprints: rectangles' corners and their penetration depth.

Poses are arrays ``(..., n, 3)`` of (x, y, yaw). The penetration of two convex footprints is the
smallest overlap of their projections over the separating axes (both rectangles' edge normals):
positive when they overlap (the distance one must move to separate them), negative when apart
(then a lower bound of their gap along the best axis).
"""

from __future__ import annotations

import numpy as np

_SIGNS = np.array([[1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0], [1.0, -1.0]])


def axes(poses: np.ndarray) -> np.ndarray:
    """Unit x and y axes of each footprint: (..., n, 2, 2)."""
    c, s = np.cos(poses[..., 2]), np.sin(poses[..., 2])
    return np.stack([np.stack([c, s], -1), np.stack([-s, c], -1)], -2)


def corners(poses: np.ndarray, half: np.ndarray) -> np.ndarray:
    """Corners of each footprint (``half``: (n, 2) half extents): (..., n, 4, 2)."""
    ax = axes(poses)
    local = _SIGNS[None, :, :] * half[:, None, :]  # (n, 4, 2)
    return (poses[..., None, :2] + local[..., 0:1] * ax[..., None, 0, :]
            + local[..., 1:2] * ax[..., None, 1, :])


def penetration(poses: np.ndarray, half: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """Penetration depth of each pair ``(i, j)`` of ``pairs`` (M, 2): (..., M). Along a test axis
    ``u`` a rectangle spans its centre's projection plus or minus ``hx |x.u| + hy |y.u|``, so the
    two overlap there by the sum of those radii minus the distance of the centres' projections."""
    if len(pairs) == 0:
        return np.zeros((*poses.shape[:-2], 0))
    ax = axes(poses)
    i, j = pairs[:, 0], pairs[:, 1]
    ai, aj = ax[..., i, :, :], ax[..., j, :, :]  # (..., M, 2, 2)
    test = np.concatenate([ai, aj], axis=-2)  # (..., M, 4, 2): both rectangles' edge normals
    d = poses[..., j, :2] - poses[..., i, :2]  # (..., M, 2)
    apart = np.abs((test * d[..., None, :]).sum(-1))  # (..., M, 4)

    def radius(own: np.ndarray, h: np.ndarray) -> np.ndarray:
        along = np.abs((test[..., :, None, :] * own[..., None, :, :]).sum(-1))  # (..., M, 4, 2)
        return (along * h[:, None, :]).sum(-1)

    return (radius(ai, half[i]) + radius(aj, half[j]) - apart).min(-1)


def to_local(point: np.ndarray, frame: np.ndarray) -> np.ndarray:
    """``point`` (..., 2) in the frame of pose ``frame`` (..., 3)."""
    d = point - frame[..., :2]
    c, s = np.cos(frame[..., 2]), np.sin(frame[..., 2])
    return np.stack([c * d[..., 0] + s * d[..., 1], -s * d[..., 0] + c * d[..., 1]], -1)


def wrap(angle: np.ndarray | float) -> np.ndarray:
    return (np.asarray(angle) + np.pi) % (2 * np.pi) - np.pi
