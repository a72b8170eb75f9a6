"""The press depth the image critic reads from the top view's depth, calibrated on the live model (a
press rolled out in MuJoCo): its robot constants hold for the model, and a full press and a light one
fall on either side of its threshold."""

from __future__ import annotations

import numpy as np
import pytest

from vcage.assets.catalog import CATALOG
from vcage.critics.image.measure import _heights
from vcage.critics.image.thresholds import DEFAULT
from vcage.scene.compose import compose
from vcage.scene.spec import ObjectSpec, SceneSpec
from vcage.sim.render import ROBOT, Renderer
from vcage.skills.base import Skills
from vcage.skills.faults import FaultConfig, FaultInjector
from vcage.skills.playback import Player
from vcage.tasks.verifier import render_views

FINGER_CONTACT, HAND_TOP, PRESS_SHARE = DEFAULT.FINGER_CONTACT, DEFAULT.HAND_TOP, DEFAULT.PRESS_SHARE

# (type, yaw, x, y, the seed of a light press the oracle does not count: a lever pressed "lightly"
# can still go past the oracle's travel)
CASES = [("bell", 0.0, 0.5, 0.05, 2), ("alarm_clock", 1.0, 0.6, -0.1, 2), ("stapler", 2.5, 0.55, 0.2, 3)]


def _press(otype: str, yaw: float, x: float, y: float,
           fault: str | None, seed: int = 0) -> tuple[float, float, float, float]:
    """(robot top over the object at the lowest moment, true TCP height, the object's top before,
    the full press depth), heights above the table from the top view's depth."""
    world = compose(SceneSpec(objects=(ObjectSpec("x", otype, (x, y), yaw=yaw),))).make_world()
    world.settle(0.3)
    with Renderer(world, 320, 240) as r:
        before = render_views(r)["top"]
        skills = Skills(world, Player(world, record_states=True),
                        fault=FaultInjector(FaultConfig(fault, seed=seed)) if fault else None)
        skills.do("press", obj="x")
        rec = skills.player.recording
        frame = int(np.argmin([p[2] for p in rec.ee_pos]))
        world.set_state(rec.states[frame])
        during = render_views(r)["top"]
    hb, hd = _heights(before), _heights(during)
    assert hb is not None and hd is not None
    mask = before.segmentation == 0
    top = float(hb[mask].max())
    point = next(p for p in CATALOG.get(otype).functional_points if p.joint)
    scale = top / point.pos[2]
    full = (point.travel if point.kind == "button" else point.stroke) * scale
    robot = float(hd[(during.segmentation == ROBOT) & mask].max())
    return robot, float(rec.ee_pos[frame][2] - world.table_top()), top, full


@pytest.mark.parametrize(("otype", "yaw", "x", "y", "seed"), CASES)
def test_the_robot_constants_hold_and_a_light_press_is_short(otype: str, yaw: float, x: float, y: float,
                                                             seed: int) -> None:
    robot, tcp, top, full = _press(otype, yaw, x, y, None)
    assert robot - tcp == pytest.approx(HAND_TOP, abs=1e-3)  # the wrist's top over the hand's centre
    assert tcp - top == pytest.approx(FINGER_CONTACT - full, abs=1.5e-3)  # a full press
    kind = next(p for p in CATALOG.get(otype).functional_points if p.joint).kind
    threshold = FINGER_CONTACT - PRESS_SHARE[kind] * full
    assert (robot - HAND_TOP) - top < threshold
    robot, _, top, _ = _press(otype, yaw, x, y, "press_light", seed)
    assert (robot - HAND_TOP) - top > threshold
