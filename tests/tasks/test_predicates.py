"""Ground-truth predicates on real MuJoCo scenes."""

from __future__ import annotations

import numpy as np

from vcage.scene.compose import compose
from vcage.scene.spec import ObjectSpec, SceneSpec
from vcage.sim.world import World
from vcage.tasks import predicates as P


def _settled(*objects: ObjectSpec) -> World:
    world = compose(SceneSpec(objects=objects)).make_world()
    world.settle(0.5)
    return world


def test_on_table_by_contact_not_by_origin_height() -> None:
    world = _settled(ObjectSpec("a", "block", (0.5, -0.1)), ObjectSpec("b", "block", (0.5, 0.1)))
    assert P.on_table(world, "a") and P.on_table(world, "b")
    # lay block a on a side face: its origin (bottom-face centre) rises by half a side
    joint = world.model.joint(world.model.body_jntadr[world.objects["a"].body_id])
    qpos = world.data.qpos[joint.qposadr[0]: joint.qposadr[0] + 7]
    qpos[3:] = [np.cos(np.pi / 4), np.sin(np.pi / 4), 0.0, 0.0]  # 90 degrees about x
    world.forward()
    world.settle(0.5)
    assert world.object_pos("a")[2] - world.table_top() > 0.015  # the old height test failed here
    assert P.on_table(world, "a", tol=0.02) and P.upright(world, "b") and not P.upright(world, "a")


def test_not_on_table_when_stacked_or_lifted() -> None:
    world = _settled(ObjectSpec("a", "block", (0.5, 0.0)),
                     ObjectSpec("b", "block", (0.5, 0.0), z=0.75 + 0.05))
    assert P.on_table(world, "a") and not P.on_table(world, "b")
    assert P.on(world, "b", "a")
