"""Top-down views of a scene: ``I_init`` with its segmentation, and the same table with no objects.

The empty table is rendered from the same world with every free object moved far out of view, so
it needs no second compile and matches ``I_init`` pixel for pixel wherever no object stood.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from vcage.scene.compose import TOP_CAMERA
from vcage.sim.camera import OrthoCamera
from vcage.sim.render import Renderer
from vcage.sim.world import World

WIDTH, HEIGHT = 640, 480
AWAY = 100.0  # metres: where objects go while the empty table is rendered


@dataclass(frozen=True)
class TopView:
    """A top-down frame: RGB, per-pixel object index into ``names`` (-1 table, -2 robot), the camera,
    and each object's pose (x, y, yaw) and resting height when it was rendered."""

    rgb: np.ndarray
    segmentation: np.ndarray
    names: tuple[str, ...]
    camera: OrthoCamera
    poses: dict[str, tuple[float, float, float]]
    heights: dict[str, float]
    table_top: float

    def mask(self, name: str) -> np.ndarray:
        return self.segmentation == self.names.index(name)


def _yaw(quat: np.ndarray) -> float:
    w, x, y, z = quat
    return float(np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)))


def render_top(world: World, width: int = WIDTH, height: int = HEIGHT) -> tuple[TopView, np.ndarray]:
    """``I_init`` of ``world`` as it stands, and the RGB of its empty table."""
    names = tuple(world.object_names)
    poses_arr = world.object_poses(names) if names else np.zeros((0, 7))
    poses = {n: (float(p[0]), float(p[1]), _yaw(p[3:])) for n, p in zip(names, poses_arr, strict=True)}
    heights = {n: float(p[2]) for n, p in zip(names, poses_arr, strict=True)}
    camera = OrthoCamera.from_world(world, TOP_CAMERA, width, height)
    with Renderer(world, width, height) as renderer:
        rgb = renderer.rgb(TOP_CAMERA)
        seg = renderer.segmentation(TOP_CAMERA)
        empty = _render_empty(world, renderer)
    view = TopView(rgb, seg, names, camera, poses, heights, world.table_top())
    return view, empty


def _render_empty(world: World, renderer: Renderer) -> np.ndarray:
    model, data = world.model, world.data
    saved = data.qpos.copy()
    try:
        for k, inst in enumerate(world.objects.values()):
            jnt = int(model.body_jntadr[inst.body_id])
            if jnt < 0 or int(model.jnt_type[jnt]) != int(mujoco.mjtJoint.mjJNT_FREE):
                continue
            adr = int(model.jnt_qposadr[jnt])
            data.qpos[adr:adr + 3] = (AWAY + k, AWAY, -AWAY)
        mujoco.mj_kinematics(model, data)
        mujoco.mj_camlight(model, data)
        return renderer.rgb(TOP_CAMERA)
    finally:
        data.qpos[:] = saved
        world.forward()
