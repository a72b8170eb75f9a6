"""The batched render model draws what the level-of-detail model draws, with fewer geoms."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from vcage.scene.compose import compose
from vcage.scene.spec import ObjectSpec, SceneSpec
from vcage.sim import batching
from vcage.sim.lod import lod_model
from vcage.sim.render import Renderer
from vcage.sim.world import World

CAMERAS = ("front", "panda/wrist", "top")


@pytest.fixture()
def cluttered() -> World:
    """Objects built from boxes, cylinders, spheres, capsules and joints (bell, clock, mug rack)."""
    objects = (ObjectSpec("bell", "bell", (0.55, 0.1)), ObjectSpec("clock", "alarm_clock", (0.5, -0.12)),
               ObjectSpec("mug", "mug", (0.62, -0.02)), ObjectSpec("rack", "mug_rack", (0.45, 0.2)),
               ObjectSpec("bottle", "bottle", (0.68, 0.18)), ObjectSpec("block", "block", (0.42, -0.25)))
    world = compose(SceneSpec(objects=objects)).make_world()
    world.settle(0.2)
    return world


def _unbatched(world: World, width: int, height: int) -> Renderer:
    return Renderer(world, width, height, batch=False)


def _postures(world: World, n: int) -> list[np.ndarray]:
    rng = np.random.default_rng(1)
    limits, home = world.robot.arm_limits, world.get_state()
    states = [home]
    for _ in range(n):
        world.show_state(home)
        world.data.qpos[world.robot.arm_qpos] = rng.uniform(limits[:, 0], limits[:, 1])
        states.append(world.get_state())
    world.set_state(home)
    return states


def test_batched_frames_are_the_level_of_detail_frames(cluttered: World) -> None:
    """RGB, segmentation and depth over arm postures and every critic and video camera: triangle
    seams may move a pixel's edge, nothing more (measured: mean difference at most 0.2 of 255)."""
    world = cluttered
    with Renderer(world, 160, 120) as batched, _unbatched(world, 160, 120) as plain:
        assert batched.model is not plain.model
        for state in _postures(world, 2):
            world.show_state(state)
            for cam in CAMERAS:
                a, b = plain.rgb(cam).astype(int), batched.rgb(cam).astype(int)
                assert np.abs(a - b).mean() < 0.5, cam
                sa, sb = plain.segmentation(cam), batched.segmentation(cam)
                assert (sa == sb).mean() > 0.999, cam
                assert set(np.unique(sa)) == set(np.unique(sb)), cam  # every object, the robot
                da, db = plain.depth(cam), batched.depth(cam)
                same = sa == sb
                assert np.percentile(np.abs(da - db)[same], 99) < 1e-3, cam


def test_the_batched_model_draws_fewer_geoms_with_the_same_bodies(cluttered: World) -> None:
    lod = lod_model(cluttered.model)
    assert cluttered.spec is not None
    model, source = batching.batched(cluttered.model, cluttered.spec)
    drawn = [int(np.isin(m.geom_group, batching.DRAWN_GROUPS).sum()) for m in (lod, model)]
    assert drawn[1] < drawn[0] / 2, drawn
    assert model.nbody == lod.nbody and model.njnt == lod.njnt and model.ncam == lod.ncam
    assert [model.body(i).name for i in range(model.nbody)] == [lod.body(i).name for i in range(lod.nbody)]
    np.testing.assert_array_equal(lod.geom_bodyid[source], model.geom_bodyid)  # each stands for its body
    assert batching.batched(cluttered.model, cluttered.spec)[0] is model  # compiled once per scene


def test_a_moved_object_is_drawn_where_it_is(cluttered: World) -> None:
    """The batched model has data of its own: each frame takes the world's poses."""
    world = cluttered
    with Renderer(world, 160, 120) as batched, _unbatched(world, 160, 120) as plain:
        before = batched.segmentation("top")
        adr = int(world.model.jnt_qposadr[world.model.joint("block/free").id])
        world.data.qpos[adr:adr + 2] += [0.1, 0.1]
        mujoco.mj_forward(world.model, world.data)
        after = batched.segmentation("top")
        block = world.object_names.index("block")
        assert not np.array_equal(before == block, after == block)
        assert np.array_equal(after, plain.segmentation("top"))


@pytest.mark.parametrize("kind", ["box", "sphere", "ellipsoid", "cylinder", "capsule"])
def test_primitives_are_tessellated_as_the_renderer_draws_them(kind: str) -> None:
    """A primitive drawn as a batched mesh shows MuJoCo's own pixels (lighting is computed at the
    corners, so a different tessellation shades large faces differently)."""
    spec = mujoco.MjSpec()
    spec.visual.quality.shadowsize = 0
    spec.worldbody.add_light(pos=[0.3, -0.2, 1.5], dir=[-0.2, 0.1, -1], castshadow=False)
    spec.worldbody.add_camera(name="c", pos=[0.6, 0, 0.5], xyaxes=[0, 1, 0, -0.6, 0, 0.8])
    body = spec.worldbody.add_body(name="b", pos=[0, 0, 0.1], quat=[0.9, 0.3, 0.2, 0.1])
    # large enough to be cut as finely as MuJoCo cuts them (SQUARE)
    size = {"box": [0.1, 0.08, 0.06], "sphere": [0.15, 0, 0], "ellipsoid": [0.15, 0.1, 0.08],
            "cylinder": [0.2, 0.2, 0], "capsule": [0.08, 0.2, 0]}[kind]
    for z in (0.0, -5.0):  # two parts, one out of view, so that the body's geoms are merged
        body.add_geom(type=getattr(mujoco.mjtGeom, f"mjGEOM_{kind.upper()}"), size=size, pos=[0, 0, z],
                      rgba=[0.8, 0.3, 0.3, 1])
    lod = lod_model(spec.compile())
    model, _ = batching.batched_model(lod, spec)
    assert int(np.isin(model.geom_group, batching.DRAWN_GROUPS).sum()) == 1

    def frame(m: mujoco.MjModel) -> np.ndarray:
        data = mujoco.MjData(m)
        mujoco.mj_forward(m, data)
        with mujoco.Renderer(m, 256, 256) as r:
            r.update_scene(data, camera="c")
            return r.render().astype(int)

    a, b = frame(lod), frame(model)
    assert (a > 0).any()
    assert np.abs(a - b).mean() < 0.01


def test_small_faces_are_one_square_and_large_ones_as_many_as_mujoco_draws() -> None:
    corners, _ = batching._box(np.array([0.02, 0.02, 0.02]), 4)  # a 4 cm cube: 6 faces, 2 triangles each
    assert len(corners) == 6 * 2 * 3
    corners, _ = batching._box(np.array([0.4, 0.6, 0.02]), 4)  # a table top: its faces 4 x 4 squares
    assert len(corners) == 6 * 16 * 2 * 3


def test_a_world_without_its_spec_draws_the_level_of_detail_copy(world: World) -> None:
    with Renderer(world, 64, 64) as r:
        assert r.model.ngeom > world.model.ngeom  # the merged geoms beside the undrawn parts
    world.spec = None
    with Renderer(world, 64, 64) as r:
        assert r.model.ngeom == world.model.ngeom
