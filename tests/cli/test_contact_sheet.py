"""The images the CLI saves come from the sim layer: rows are states, columns cameras."""

from __future__ import annotations

import numpy as np
import pytest

from vcage.errors import ConfigError
from vcage.sim.render import Renderer, contact_sheet
from vcage.sim.world import World


def test_contact_sheet_rows_are_states_and_the_state_is_restored(world: World) -> None:
    start = world.get_state()
    for _ in range(20):
        world.step()
    end = world.get_state()
    with Renderer(world, 64, 48) as r:
        as_is = [r.rgb(c) for c in ("front", "top")]
    sheet = contact_sheet(world, [start, None], ["front", "top"], 64, 48)
    assert sheet.shape == (96, 128, 3) and sheet.dtype == np.uint8
    assert np.array_equal(sheet[48:], np.concatenate(as_is, 1))  # None: the world as it stands
    np.testing.assert_array_equal(world.get_state(), end)
    world.set_state(start)
    with Renderer(world, 64, 48) as r:
        assert np.array_equal(sheet[:48, 64:], r.rgb("top"))


def test_contact_sheet_needs_a_state_and_a_camera(world: World) -> None:
    with pytest.raises(ConfigError):
        contact_sheet(world, [], ["front"])
    with pytest.raises(ConfigError):
        contact_sheet(world, [None], [])
