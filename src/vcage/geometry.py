"""Small rigid-body geometry helpers on numpy arrays (quaternions are w, x, y, z)."""

from __future__ import annotations

import math

import numpy as np


def rot_x(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1.0, 0], [-s, 0, c]])


def rot_z(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def yaw_quat(yaw: float) -> np.ndarray:
    return np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])


def mat_to_quat(mat: np.ndarray) -> np.ndarray:
    """Rotation matrix to a unit quaternion with non-negative w."""
    m = np.asarray(mat, dtype=float).reshape(3, 3)
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        q = [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        q = [(m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s]
    elif m[1, 1] > m[2, 2]:
        s = math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        q = [(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s]
    else:
        s = math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        q = [(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s]
    qa = np.array(q)
    qa /= np.linalg.norm(qa)
    return qa if qa[0] >= 0 else -qa


def quat_to_mat(quat: np.ndarray) -> np.ndarray:
    w, x, y, z = np.asarray(quat, dtype=float) / np.linalg.norm(quat)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def euler_quat(rx: float, ry: float, rz: float) -> np.ndarray:
    """Quaternion of the rotation ``Rz(rz) @ Ry(ry) @ Rx(rx)``."""
    return mat_to_quat(rot_z(rz) @ rot_y(ry) @ rot_x(rx))


def yaw_of(mat: np.ndarray) -> float:
    """Heading of a rotation's x axis in the world xy plane."""
    m = np.asarray(mat).reshape(3, 3)
    return math.atan2(m[1, 0], m[0, 0])


def tilt_of(mat: np.ndarray) -> float:
    """Angle between a body's z axis and world up (0 when upright)."""
    m = np.asarray(mat).reshape(3, 3)
    return math.acos(max(-1.0, min(1.0, m[2, 2])))


def wrap_angle(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


def wrap_half_turn(a: float) -> float:
    """The smallest turn, within +-pi/2, equal to ``a`` up to half turns (for headings of objects
    that look the same turned by pi)."""
    return wrap_angle(2 * wrap_angle(a)) / 2


def look_at_quat(pos: np.ndarray, target: np.ndarray,
                 up: tuple[float, float, float] = (0.0, 0.0, 1.0)) -> np.ndarray:
    """Orientation of a MuJoCo camera (looking along its -z) at ``pos`` aimed at ``target``.

    ``up`` is the direction that should appear upwards in the image.
    """
    back = np.asarray(pos, float) - np.asarray(target, float)
    back /= np.linalg.norm(back)
    right = np.cross(np.asarray(up, float), back)
    if np.linalg.norm(right) < 1e-6:  # up is parallel to the view axis: pick any right vector
        right = np.cross([1.0, 0.0, 0.0], back)
    right /= np.linalg.norm(right)
    return mat_to_quat(np.column_stack([right, np.cross(back, right), back]))
