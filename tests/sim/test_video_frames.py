"""Rendering a recording: one state per frame for all cameras, kinematics only, same pixels."""

from __future__ import annotations

import numpy as np
import pytest

from vcage.errors import ConfigError
from vcage.sim.render import Renderer
from vcage.sim.robot import HOME_QPOS
from vcage.sim.world import World


def _recording(world: World, steps: int = 6) -> list[np.ndarray]:
    ctrl = world.robot.ctrl(HOME_QPOS + 0.3, 0.0)
    states = []
    for _ in range(steps):
        world.step(ctrl)
        states.append(world.get_state())
    return states


def test_show_state_puts_everything_drawn_where_set_state_does(world: World) -> None:
    states = _recording(world)
    for state in states[::2]:
        world.set_state(state)
        expected = [world.data.xpos.copy(), world.data.geom_xpos.copy(), world.data.cam_xpos.copy(),
                    world.data.light_xpos.copy(), world.data.geom_xmat.copy()]
        world.reset()
        world.show_state(state)
        shown = [world.data.xpos, world.data.geom_xpos, world.data.cam_xpos, world.data.light_xpos,
                 world.data.geom_xmat]
        for a, b in zip(expected, shown, strict=True):
            np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("detail", ["full", "lod"])
def test_rgb_states_matches_frame_by_frame_rendering(world: World, detail: str) -> None:
    states = _recording(world)[:-1]  # the world is one step further
    final = world.get_state()
    cameras = ("front", "panda/wrist")
    with Renderer(world, 64, 48, detail) as r:
        frames = r.rgb_states(states, cameras)
        np.testing.assert_array_equal(world.get_state(), final)  # the world is restored
        for cam in cameras:
            assert frames[cam].shape == (len(states), 48, 64, 3) and frames[cam].dtype == np.uint8
        for i, state in enumerate(states):
            world.set_state(state)
            for cam in cameras:
                np.testing.assert_array_equal(frames[cam][i], r.rgb(cam), err_msg=f"{cam} frame {i}")
        assert not np.array_equal(frames["front"][0], frames["front"][-1])  # the arm moved
        with pytest.raises(ConfigError, match="unknown camera"):
            r.rgb_states(states, ("front", "ceiling"))
        with pytest.raises(ConfigError, match="at least one camera"):
            r.rgb_states(states, ())
