"""Compose a :class:`SceneSpec` into a compiled MuJoCo model with ``MjSpec``.

Objects are built from the catalog with their instance names as prefixes. Compiled models are
cached by scene spec, so repeated episodes of an unrandomised task compile once.
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass
from functools import partial

import mujoco
import numpy as np

from vcage.assets.catalog import CATALOG, ObjectType
from vcage.assets.parts import PartBuilder
from vcage.config import OFFSCREEN_SIZE, SimConfig
from vcage.geometry import look_at_quat, yaw_quat
from vcage.scene.spec import ROBOT_MOUNT, SceneSpec, TableSpec
from vcage.sim.robot import GRIPPER_OPEN, HOME_QPOS, Robot, attach_panda
from vcage.sim.world import ObjectInstance, World

TABLE_BODY = "table"
# Static cameras: name -> (position relative to the table centre at nominal height, target).
CAMERAS = {
    "front": ((1.55, 0.0, 1.35), (0.5, 0.0, 0.76)),
    "overview": ((0.3, 0.95, 1.5), (0.6, 0.0, 0.75)),
}
TOP_CAMERA = "top"
TOP_CAMERA_HEIGHT = 1.5  # above the table top
ARENA_BASE = 32 * 2**20  # bytes of MuJoCo arena (contacts, constraints) per scene ...
ARENA_PER_OBJECT = 4 * 2**20  # ... plus this per object


@dataclass(frozen=True)
class ComposedScene:
    model: mujoco.MjModel
    objects: dict[str, ObjectInstance]
    spec: SceneSpec
    sim: SimConfig = SimConfig()  # what ``model`` was compiled with

    def make_world(self, sim: SimConfig = SimConfig()) -> World:
        return World(self.model, self.objects, sim, partial(scene_spec, self.spec, self.sim))


def _base_spec(sim: SimConfig) -> mujoco.MjSpec:
    spec = mujoco.MjSpec()
    spec.modelname = "vcage_scene"
    spec.option.timestep = sim.timestep
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.noslip_iterations = sim.noslip_iterations
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.impratio = 10
    vis = spec.visual
    vis.quality.shadowsize = 0
    vis.quality.offsamples = 0
    vis.global_.offwidth, vis.global_.offheight = OFFSCREEN_SIZE
    vis.headlight.ambient = [0.35, 0.35, 0.35]
    vis.headlight.diffuse = [0.3, 0.3, 0.3]
    spec.add_texture(name="floor_tex", type=mujoco.mjtTexture.mjTEXTURE_2D,
                     builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER, width=256, height=256,
                     rgb1=[0.25, 0.27, 0.3], rgb2=[0.32, 0.34, 0.38])
    spec.add_material(name="floor_mat", textures=["", "floor_tex"], texrepeat=[4, 4],
                      texuniform=True)
    spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[3, 3, 0.1],
                            material="floor_mat")
    pedestal_h = ROBOT_MOUNT[2]
    spec.worldbody.add_geom(name="pedestal", type=mujoco.mjtGeom.mjGEOM_BOX,
                            size=[0.12, 0.12, pedestal_h / 2],
                            pos=[ROBOT_MOUNT[0] - 0.04, ROBOT_MOUNT[1], pedestal_h / 2],
                            rgba=[0.2, 0.2, 0.22, 1])
    attach_panda(spec, ROBOT_MOUNT)
    return spec


def _add_table(spec: mujoco.MjSpec, table: TableSpec) -> None:
    kw: dict = {"rgba": list(table.rgba)}
    if table.texture != "plain":
        builtin = {"checker": mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
                   "grid": mujoco.mjtBuiltin.mjBUILTIN_FLAT}[table.texture]
        c = np.array(table.rgba[:3])
        spec.add_texture(name="table_tex", type=mujoco.mjtTexture.mjTEXTURE_2D, builtin=builtin,
                         mark=mujoco.mjtMark.mjMARK_EDGE, markrgb=(c * 0.6).tolist(),
                         width=256, height=256, rgb1=c.tolist(), rgb2=(c * 0.85).tolist())
        spec.add_material(name="table_mat", textures=["", "table_tex"], texrepeat=[3, 3],
                          texuniform=True)
        kw = {"material": "table_mat"}
    half_t = table.thickness / 2
    body = spec.worldbody.add_body(name=TABLE_BODY, pos=[table.center_x, 0, table.height - half_t])
    hx, hy = table.size[0] / 2, table.size[1] / 2
    body.add_geom(name="table/top", type=mujoco.mjtGeom.mjGEOM_BOX, size=[hx, hy, half_t],
                  friction=[1.0, 0.005, 0.0001], **kw)
    leg_h = (table.height - table.thickness) / 2
    for i, (sx, sy) in enumerate(((1, 1), (1, -1), (-1, 1), (-1, -1))):
        body.add_geom(name=f"table/leg{i}", type=mujoco.mjtGeom.mjGEOM_BOX,
                      size=[0.025, 0.025, leg_h],
                      pos=[sx * (hx - 0.05), sy * (hy - 0.05), -half_t - leg_h],
                      rgba=[0.3, 0.25, 0.2, 1])


def _add_cameras(spec: mujoco.MjSpec, scene: SceneSpec) -> None:
    off = np.asarray(scene.camera_offset)
    dz = scene.table.height - 0.75
    for name, (pos, target) in CAMERAS.items():
        p = np.asarray(pos) + off + [0, 0, dz]
        t = np.asarray(target) + [0, 0, dz]
        spec.worldbody.add_camera(name=name, pos=p.tolist(), quat=look_at_quat(p, t).tolist(),
                                  fovy=50.0)
    top = [scene.table.center_x, 0.0, scene.table.height + TOP_CAMERA_HEIGHT]
    spec.worldbody.add_camera(name=TOP_CAMERA, pos=top, quat=look_at_quat(np.array(top),
                              np.array(top) - [0, 0, 1], up=(1.0, 0.0, 0.0)).tolist(),
                              proj=mujoco.mjtProjection.mjPROJ_ORTHOGRAPHIC,
                              fovy=max(scene.table.size[0], scene.table.size[1] * 0.75))


def _add_object(spec: mujoco.MjSpec, obj_type: ObjectType, name: str, pos: list[float],
                yaw: float, scale: float, rgba: tuple, friction: float) -> mujoco.MjsBody:
    body = spec.worldbody.add_body(name=name, pos=pos, quat=yaw_quat(yaw).tolist())
    if not obj_type.fixed:
        body.add_freejoint(name=f"{name}/free")
    sx, sy, sz = (s * scale for s in obj_type.size)
    mass = obj_type.mass * scale**3
    body.mass = mass
    body.ipos = [0.0, 0.0, sz / 2]
    body.inertia = [mass * (sy**2 + sz**2) / 12, mass * (sx**2 + sz**2) / 12,
                    mass * (sx**2 + sy**2) / 12]
    body.explicitinertial = True
    obj_type.build(PartBuilder(body, name, scale, rgba, friction))
    return body


def compose(scene: SceneSpec, sim: SimConfig = SimConfig()) -> ComposedScene:
    """Compile ``scene`` into a model with a ``home`` keyframe (robot at home, objects placed)."""
    key = _cache_key(scene, sim)
    cached = _MODEL_CACHE.get(key)
    if cached is not None:
        _MODEL_CACHE.move_to_end(key)
        return cached
    types = {o.name: CATALOG.get(o.type) for o in scene.objects}
    spec = scene_spec(scene, sim)
    model = spec.compile()
    _set_home_key(model)
    objects = {
        o.name: ObjectInstance(o.name, o.type, model.body(o.name).id, o.scale,
                               o.color or next(iter(types[o.name].colors)))
        for o in scene.objects
    }
    composed = ComposedScene(model, objects, scene, sim)
    _MODEL_CACHE[key] = composed
    if len(_MODEL_CACHE) > _CACHE_SIZE:
        _MODEL_CACHE.popitem(last=False)
    return composed


def scene_spec(scene: SceneSpec, sim: SimConfig = SimConfig()) -> mujoco.MjSpec:
    """The ``MjSpec`` that :func:`compose` compiles (built afresh each call: MuJoCo caches the
    meshes, so this is cheap; a spec kept after compiling holds tens of MiB)."""
    spec = _base_spec(sim)
    _add_table(spec, scene.table)
    _add_cameras(spec, scene)
    spec.worldbody.add_light(name="key", pos=[0.6, -0.4, 2.6], dir=[-0.1, 0.2, -1.0],
                             diffuse=[scene.light] * 3, specular=[0.1, 0.1, 0.1],
                             castshadow=False)
    for obj in scene.objects:
        z = scene.table.height if obj.z is None else obj.z
        otype = CATALOG.get(obj.type)
        _add_object(spec, otype, obj.name, [obj.xy[0], obj.xy[1], z], obj.yaw, obj.scale,
                    otype.color(obj.color), obj.friction)
    spec.add_key(name="home")
    # Room for the contacts of a cluttered (or badly placed) scene; pages are only touched as used.
    spec.memory = ARENA_BASE + ARENA_PER_OBJECT * len(scene.objects)
    return spec


def _set_home_key(model: mujoco.MjModel) -> None:
    """Fill the ``home`` keyframe: objects at their composed poses, robot at home, hand open."""
    robot = Robot(model)
    key = model.key("home")
    key.qpos[:] = model.qpos0
    key.qpos[robot.arm_qpos] = HOME_QPOS
    key.qpos[robot.finger_qpos] = GRIPPER_OPEN
    key.ctrl[:] = robot.ctrl(HOME_QPOS, 1.0)


# Each compiled scene holds about 24 MiB (mostly the robot meshes and their bounding-volume
# hierarchies). Randomised scenes never repeat, so the cache only serves an attempt that compiles
# and then realizes its scene, and unrandomised tasks that rebuild one scene: a few entries do.
_CACHE_SIZE = 2
_MODEL_CACHE: OrderedDict[tuple, ComposedScene] = OrderedDict()


def _cache_key(scene: SceneSpec, sim: SimConfig) -> tuple:
    return (scene, sim)
