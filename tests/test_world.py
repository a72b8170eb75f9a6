from __future__ import annotations

import numpy as np
import pytest

from vcage.errors import SceneError, SimulationError
from vcage.scene.compose import compose
from vcage.scene.spec import ObjectSpec, SceneSpec, TableSpec
from vcage.sim.render import Renderer
from vcage.sim.robot import HOME_QPOS
from vcage.sim.world import World


def test_home_keyframe_and_objects_rest(world: World) -> None:
    np.testing.assert_allclose(world.robot.arm_q(world.data), HOME_QPOS)
    world.settle(0.5)
    np.testing.assert_allclose(world.robot.arm_q(world.data), HOME_QPOS, atol=0.01)
    assert abs(world.object_pos("a")[2] - world.table_top()) < 0.002


def test_state_restore_replays_exactly(world: World) -> None:
    ctrl = world.robot.ctrl(HOME_QPOS + 0.2, 0.0)
    start = world.get_state()
    for _ in range(20):
        world.step(ctrl)
    first = world.data.qpos.copy()
    world.set_state(start)
    for _ in range(20):
        world.step(ctrl)
    np.testing.assert_array_equal(world.data.qpos, first)


def test_physics_time_is_counted_per_step(world: World) -> None:
    start = world.physics_seconds
    world.forward()
    assert world.physics_seconds == start  # only stepping counts as physics
    world.settle(0.1)
    assert world.physics_seconds > start


def test_instability_is_detected(world: World) -> None:
    world.data.qvel[world.model.joint("a/free").dofadr[0]] = 1e6
    with pytest.raises(SimulationError, match="a/free"):
        world.step()
    world.reset()
    world.settle(0.5)
    world.data.qpos[0] = np.nan
    # MuJoCo resets the data it finds broken (its clock too): the error says when it broke
    with pytest.raises(SimulationError, match=r"unstable near t=0\.500s"):
        world.step()


def test_table_height_and_unknown_object() -> None:
    spec = SceneSpec(objects=(ObjectSpec("a", "block", (0.5, 0.0)),), table=TableSpec(height=0.8))
    world = compose(spec).make_world()
    assert abs(world.table_top() - 0.8) < 1e-9
    with pytest.raises(SceneError, match="objects: \\['a'\\]"):
        world.object("mug")
    with pytest.raises(SceneError):
        TableSpec(height=2.0)


def test_render_rgb_depth_and_segmentation(world: World) -> None:
    with Renderer(world, 128, 96) as r:
        for cam in ("front", "overview", "panda/wrist"):
            frame = r.frame(cam, depth=True, segmentation=True)
            assert frame.rgb.shape == (96, 128, 3) and frame.rgb.dtype == np.uint8
            assert frame.depth is not None and frame.depth.shape == (96, 128)
            assert np.all(np.isfinite(frame.depth)) and 0.01 < frame.depth.min() < 5.0
        assert r.rgb("top").shape == (96, 128, 3)
        seg = r.segmentation("top")
        # both blocks are visible from the top and mapped to their object index; the robot is -2
        assert set(np.unique(seg)) == {-2, -1, 0, 1}
        # block "b" is at +y, i.e. on the image's left half in the top view (+x is up)
        cols = np.nonzero(seg == world.object_names.index("b"))[1]
        assert cols.mean() < 64
        # block "a" lies near the front camera's view axis, about 1.2 m away
        depth, seg_front = r.depth("front"), r.segmentation("front")
        cam = world.data.cam_xpos[world.model.camera("front").id]
        expected = np.linalg.norm(world.object_pos("a") + [0, 0, 0.0225] - cam)
        assert abs(np.median(depth[seg_front == 0]) - expected) < 0.05
    with pytest.raises(Exception, match="closed"):
        r.rgb("top")


def test_depth_from_the_orthographic_top_camera_is_the_height_below_it() -> None:
    spec = SceneSpec(objects=(ObjectSpec("block", "block", (0.55, 0.0)),
                              ObjectSpec("cup", "cup", (0.6, -0.2)), ObjectSpec("bell", "bell", (0.5, 0.2))))
    world = compose(spec).make_world()
    world.settle(0.3)
    cam_z = world.data.cam_xpos[world.model.camera("top").id][2]
    with Renderer(world, 320, 240) as r:
        heights = cam_z - r.depth("top") - world.table_top()
        seg = r.segmentation("top")
    assert np.median(heights[seg == -1]) == pytest.approx(0.0, abs=1e-3)  # the table top
    for name, top in (("block", 0.045), ("cup", 0.09), ("bell", 0.06)):  # catalog heights
        assert heights[seg == world.object_names.index(name)].max() == pytest.approx(top, abs=2e-3), name


@pytest.mark.parametrize("center_x", [0.6, 0.75])
def test_the_top_views_robot_pixel_places_objects_where_they_stand(center_x: float) -> None:
    """The robot's base pixel (the top view's calibration) and the pixel size put an object's pixels
    where it stands: image up is +x (away from the robot), image right is -y; on a table whose centre
    (and so the camera's) lies elsewhere, the base's pixel moves and the objects' still agree."""
    blocks = (ObjectSpec("near", "block", (0.45, 0.15)), ObjectSpec("far", "block", (0.7, -0.2)))
    spec = SceneSpec(objects=blocks, table=TableSpec(center_x=center_x))
    world = compose(spec).make_world()
    world.settle(0.2)
    with Renderer(world, 320, 240) as r:
        base, size, seg = r.robot_pixel("top"), r.pixel_size("top"), r.segmentation("top")
        assert r.robot_pixel("front") is None  # a perspective view has no such calibration
    assert base is not None and size is not None
    for name in ("near", "far"):
        rows, cols = np.nonzero(seg == world.object_names.index(name))
        x, y = world.object_com(name)[:2]
        assert rows.mean() == pytest.approx(base[0] - x / size, abs=1.0), name
        assert cols.mean() == pytest.approx(base[1] - y / size, abs=1.0), name
