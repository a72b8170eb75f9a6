"""The exact geometry of an orthographic camera, read from the MuJoCo model: pixels <-> table points.

MuJoCo's orthographic camera looks along its -z axis; ``fovy`` is the height of the view in metres;
image columns run along the camera's +x axis and rows down its -y axis. Pixel ``(u, v)`` (column,
row, integer at pixel centres) sees the world point
``pos + (u + 0.5 - W/2) * s * x_cam + (H/2 - v - 0.5) * s * y_cam`` with ``s = fovy / H``, moved
along the view axis to the plane asked for. Nothing here assumes which world axis the image shows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from vcage.errors import ConfigError
from vcage.sim.world import World


@dataclass(frozen=True)
class OrthoCamera:
    pos: tuple[float, float, float]
    axes: tuple[tuple[float, float, float], ...]  # camera x, y, z in world coordinates (rows)
    view_height: float  # metres (MuJoCo's fovy of an orthographic camera)
    width: int
    height: int

    @classmethod
    def from_world(cls, world: World, camera: str, width: int, height: int) -> OrthoCamera:
        model = world.model
        cam = _orthographic(model, camera)
        mujoco.mj_kinematics(model, world.data)
        mujoco.mj_camlight(model, world.data)
        return cls._posed(model, cam, world.data.cam_xpos[cam], world.data.cam_xmat[cam], width, height)

    @classmethod
    def fixed(cls, model: mujoco.MjModel, camera: str, width: int, height: int) -> OrthoCamera:
        """The camera of ``model`` fixed in the world (on its world body), read from the model alone:
        no simulator data is computed or touched."""
        cam = _orthographic(model, camera)
        if int(model.cam_bodyid[cam]) != 0:
            raise ConfigError(f"camera {camera!r} moves with a body; its pose needs the simulator's data")
        mat = np.zeros(9)
        mujoco.mju_quat2Mat(mat, model.cam_quat[cam])
        return cls._posed(model, cam, model.cam_pos[cam], mat, width, height)

    @classmethod
    def _posed(cls, model: mujoco.MjModel, cam: int, pos: np.ndarray, mat: np.ndarray, width: int,
               height: int) -> OrthoCamera:
        """Camera ``cam`` of ``model`` at world position ``pos`` with rotation ``mat`` (9, row-major)."""
        rot = np.asarray(mat).reshape(3, 3)
        axes = tuple(tuple(float(v) for v in rot[:, i]) for i in range(3))
        return cls(tuple(float(v) for v in pos), axes,  # type: ignore[arg-type]
                   float(model.cam_fovy[cam]), width, height)

    @property
    def pixel_size(self) -> float:
        """Metres per pixel."""
        return self.view_height / self.height

    def _plane(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        x, y, z = (np.asarray(a) for a in self.axes)
        return np.asarray(self.pos), x, y, z

    def to_world(self, uv: np.ndarray, z: float) -> np.ndarray:
        """World (x, y) on the horizontal plane at height ``z`` seen at pixels ``uv`` (N, 2)."""
        pos, x, y, view = self._plane()
        uv = np.atleast_2d(np.asarray(uv, dtype=float))
        s = self.pixel_size
        p = (pos[None] + ((uv[:, :1] + 0.5 - self.width / 2) * s) * x[None]
             + ((self.height / 2 - uv[:, 1:2] - 0.5) * s) * y[None])
        if abs(view[2]) < 1e-9:
            raise ConfigError("the camera's view axis is horizontal: it sees no table plane")
        t = (p[:, 2] - z) / view[2]  # move along -view (the looking direction) to height z
        return (p - t[:, None] * view[None])[:, :2]

    def to_pixel(self, xy: np.ndarray, z: float) -> np.ndarray:
        """Pixel (u, v) of world points (x, y) at height ``z``, (N, 2)."""
        pos, x, y, _ = self._plane()
        xy = np.atleast_2d(np.asarray(xy, dtype=float))
        p = np.column_stack([xy, np.full(len(xy), z)]) - pos[None]
        s = self.pixel_size
        u = p @ x / s + self.width / 2 - 0.5
        v = self.height / 2 - 0.5 - p @ y / s
        return np.column_stack([u, v])

    def linear(self) -> np.ndarray:
        """The 2x2 map from a world (dx, dy) on the table to a pixel (du, dv)."""
        return self.to_pixel(np.array([[1.0, 0.0], [0.0, 1.0]]), 0.0) - self.to_pixel(np.zeros((1, 2)), 0.0)

    def image_angle(self, yaw_change: float) -> float:
        """The rotation (degrees, OpenCV's sense: counter-clockwise as displayed) of an object's
        pixels when it turns by ``yaw_change`` radians about the vertical."""
        return math.degrees(yaw_change) * self.handedness()

    def handedness(self) -> float:
        """+1 if a counter-clockwise turn seen from above is counter-clockwise on screen, else -1.

        OpenCV's positive angle is counter-clockwise as displayed, in pixel coordinates whose v axis
        points down: that is a negative-determinant frame relative to (u, -v)."""
        return 1.0 if np.linalg.det(self.linear()) < 0 else -1.0

    def to_dict(self) -> dict[str, object]:
        return {"pos": self.pos, "axes": self.axes, "view_height": self.view_height, "width": self.width,
                "height": self.height, "pixel_size": self.pixel_size}


def _orthographic(model: mujoco.MjModel, camera: str) -> int:
    """The id of ``model``'s camera ``camera``; ConfigError if it is not orthographic."""
    cam = int(model.camera(camera).id)
    if int(model.cam_projection[cam]) != int(mujoco.mjtProjection.mjPROJ_ORTHOGRAPHIC):
        raise ConfigError(f"camera {camera!r} is not orthographic")
    return cam
