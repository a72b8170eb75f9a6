"""Offscreen rendering of RGB, depth and object segmentation from any camera.

Segmentation maps every pixel to the index of a catalog object instance (``world.object_names``),
:data:`ROBOT` (-2) for the robot, or -1 for the table and background. Renderers hold GL contexts:
close them explicitly or use
them as context managers. By default heavy visual meshes (the robot's) are drawn simplified
(:mod:`vcage.sim.lod`); ``mesh_detail="full"`` draws them as shipped.
"""

from __future__ import annotations

import contextlib
from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from vcage.errors import ConfigError
from vcage.sim.batching import batched
from vcage.sim.camera import OrthoCamera
from vcage.sim.lod import render_model
from vcage.sim.world import World

ROBOT = -2  # segmentation label of the robot's pixels
NONE = -1  # table, floor, background


@dataclass(frozen=True)
class CameraFrame:
    rgb: np.ndarray  # (H, W, 3) uint8
    depth: np.ndarray | None = None  # (H, W) float32 metres
    segmentation: np.ndarray | None = None  # (H, W) int32 object index, -1 for none


class Renderer:
    """Renders a :class:`World` at a fixed resolution; dataset quality (no shadows) by default.

    ``mesh_detail`` (see :data:`vcage.config.MESH_DETAILS`) picks the model drawn: the world's own,
    or a copy with simplified visual meshes that draws the world's data; with ``batch`` (and a world
    that knows its ``MjSpec``) that copy's geoms are merged per body and look
    (:mod:`vcage.sim.batching`: the same pixels with fewer draw calls).
    """

    def __init__(self, world: World, width: int = 320, height: int = 240, mesh_detail: str = "lod",
                 batch: bool = True) -> None:
        model = world.model
        if width > model.vis.global_.offwidth or height > model.vis.global_.offheight:
            raise ConfigError(
                f"render size {width}x{height} exceeds the offscreen buffer "
                f"{model.vis.global_.offwidth}x{model.vis.global_.offheight}"
            )
        self.world = world
        self.width, self.height = width, height
        # What is drawn (never stepped), the geom of the world's model each drawn geom stands for
        # (segmentation), and the data drawn: the world's own, or for a batched model (geoms of its
        # own) its own data, set to the world's poses before each frame
        self._source: np.ndarray | None = None
        self._data = world.data
        if mesh_detail == "lod" and batch and world.spec is not None:
            self.model, self._source = batched(model, world.spec)
            self._data = mujoco.MjData(self.model)
        else:
            self.model = render_model(model, mesh_detail)
        self._renderer: mujoco.Renderer | None = mujoco.Renderer(self.model, height, width)
        self._cameras = {model.camera(i).name for i in range(model.ncam)}
        self._robot_pixels: dict[str, tuple[float, float] | None] = {}

    def _check(self, camera: str) -> mujoco.Renderer:
        if self._renderer is None:
            raise ConfigError("renderer is closed")
        if camera not in self._cameras:
            raise ConfigError(f"unknown camera {camera!r}; cameras: {sorted(self._cameras)}")
        return self._renderer

    def _drawn(self) -> mujoco.MjData:
        """The data to draw: the world's, or the batched model's set to the world's poses."""
        data, world = self._data, self.world.data
        if data is not world:
            data.qpos[:] = world.qpos
            data.mocap_pos[:] = world.mocap_pos
            data.mocap_quat[:] = world.mocap_quat
            mujoco.mj_kinematics(self.model, data)
            mujoco.mj_camlight(self.model, data)
        return data

    def _orthographic(self, camera: str) -> bool:
        self._check(camera)
        model = self.world.model
        projection = int(model.cam_projection[model.camera(camera).id])
        return projection == int(mujoco.mjtProjection.mjPROJ_ORTHOGRAPHIC)

    def _render(self, camera: str, mode: str) -> np.ndarray:
        """A frame in ``mode`` (``depth`` or ``segmentation``), switched back to RGB afterwards."""
        r = self._check(camera)
        getattr(r, f"enable_{mode}_rendering")()
        try:
            r.update_scene(self._drawn(), camera=camera)
            return r.render()
        finally:
            getattr(r, f"disable_{mode}_rendering")()

    def rgb(self, camera: str) -> np.ndarray:
        r = self._check(camera)
        r.update_scene(self._drawn(), camera=camera)
        return r.render()

    def depth(self, camera: str) -> np.ndarray:
        """Distance along the view axis in metres, from any camera: for the orthographic ``top``
        camera it is the height below the camera, so the camera's height minus it is the height of
        what each pixel sees (``tests/sim/test_render.py`` holds it to known object heights)."""
        self._check(camera)
        return self._render(camera, "depth").astype(np.float32)

    def pixel_size(self, camera: str) -> float | None:
        """Metres per pixel of an orthographic camera (its ``fovy`` is the view's height in
        metres); None for a perspective camera, whose scale varies with depth."""
        if not self._orthographic(camera):
            return None
        return float(self.world.model.cam_fovy[self.world.model.camera(camera).id]) / self.height

    def robot_pixel(self, camera: str) -> tuple[float, float] | None:
        """(row, column) at which the robot's base stands in an orthographic camera's view fixed in
        the world (its hand-eye calibration: the point may lie outside the image); None for other
        cameras. Both stand still, so it is worked out once per camera."""
        if camera not in self._robot_pixels:
            self._robot_pixels[camera] = self._calibrate(camera)
        return self._robot_pixels[camera]

    def _calibrate(self, camera: str) -> tuple[float, float] | None:
        if not self._orthographic(camera) or int(self.world.model.cam_bodyid[
                self.world.model.camera(camera).id]) != 0:
            return None
        model, base = self.world.model, self.world.robot.base_body
        if int(model.body_parentid[base]) != 0:
            raise ConfigError("the robot's base is not fixed in the world: its pixel needs simulator data")
        cam = OrthoCamera.fixed(model, camera, self.width, self.height)
        u, v = cam.to_pixel(model.body_pos[base][None, :2], float(model.body_pos[base][2]))[0]
        return float(v), float(u)

    def segmentation(self, camera: str) -> np.ndarray:
        """Per-pixel object index into ``world.object_names``; :data:`ROBOT` for the robot, else -1."""
        seg = self._render(camera, "segmentation")
        ids, types = seg[..., 0], seg[..., 1]
        out = np.full(ids.shape, -1, dtype=np.int32)
        is_geom = (types == int(mujoco.mjtObj.mjOBJ_GEOM)) & (ids >= 0)
        geoms = ids[is_geom] if self._source is None else self._source[ids[is_geom]]
        out[is_geom] = self.world.object_of_geom(geoms)
        robot = np.zeros_like(is_geom)
        robot[is_geom] = self.world.geom_is_robot(geoms)
        out[robot] = ROBOT
        return out

    def rgb_states(self, states: Sequence[np.ndarray] | np.ndarray,
                   cameras: Sequence[str]) -> dict[str, np.ndarray]:
        """RGB frames of ``cameras`` at each of ``states`` (a recording): camera -> ``(len(states),
        height, width, 3)`` uint8. Each state is set once for all cameras with only the poses
        drawing needs (:meth:`World.show_state`); the world's state is restored after."""
        if not cameras:
            raise ConfigError("name at least one camera to render")
        renderer = [self._check(camera) for camera in cameras][0]
        out = {c: np.empty((len(states), self.height, self.width, 3), np.uint8) for c in cameras}
        current = self.world.get_state()
        try:
            for i, state in enumerate(states):
                self.world.show_state(state)
                data = self._drawn()
                for camera in cameras:
                    renderer.update_scene(data, camera=camera)
                    renderer.render(out=out[camera][i])
        finally:
            self.world.set_state(current)
        return out

    def frame(self, camera: str, depth: bool = False, segmentation: bool = False) -> CameraFrame:
        return CameraFrame(
            rgb=self.rgb(camera),
            depth=self.depth(camera) if depth else None,
            segmentation=self.segmentation(camera) if segmentation else None,
        )

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    def __enter__(self) -> Renderer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:  # a safety net only; callers close explicitly
        with contextlib.suppress(Exception):  # interpreter shutdown may have torn GL down
            self.close()


def contact_sheet(world: World, states: Sequence[np.ndarray | None], cameras: Sequence[str],
                  width: int = 320, height: int = 240) -> np.ndarray:
    """One RGB image of ``world`` seen from ``cameras`` at each of ``states``.

    Row ``i`` is ``states[i]`` and column ``j`` is ``cameras[j]``, each view ``width`` x
    ``height``: the result is ``(len(states) * height, len(cameras) * width, 3)`` uint8. A state
    of ``None`` is the world as it stands, rendered before any other state is set and without
    recomputing its derived quantities (after a step, body poses lag the integration state by
    that step, which re-setting the state would change). The world's state is restored after.
    """
    if not states or not cameras:
        raise ConfigError("a contact sheet needs at least one state and one camera")
    rows: list[list[np.ndarray]] = [[] for _ in states]
    with Renderer(world, width, height) as renderer:
        for i, state in enumerate(states):
            if state is None:
                rows[i] = [renderer.rgb(c) for c in cameras]
        if any(state is not None for state in states):
            current = world.get_state()
            try:
                for i, state in enumerate(states):
                    if state is not None:
                        world.set_state(state)
                        rows[i] = [renderer.rgb(c) for c in cameras]
            finally:
                world.set_state(current)
    return np.concatenate([np.concatenate(row, 1) for row in rows], 0)
