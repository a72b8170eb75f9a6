"""Hang the mug on the rack's peg by its handle."""

from __future__ import annotations

from typing import Any

import numpy as np

from vcage.assets.catalog import CATALOG
from vcage.assets.objects.containers import MUG_HANDLE_X, MUG_HANDLE_Z, MUG_R
from vcage.geometry import wrap_angle
from vcage.scene.layout import Region, ReservedZone
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.tasks import predicates as P
from vcage.tasks.base import TASKS, AtomicTask, Item
from vcage.tasks.library._support import heading

HOLE = ((MUG_R + MUG_HANDLE_X - 0.004) / 2, 0.0, MUG_HANDLE_Z)  # middle of the handle's opening
BEFORE = 0.035  # the opening waits this far beyond the peg's end before threading
ON_PEG = 0.03  # and ends this far along the peg from its end
DROP = 0.022  # the handle's top bar is then lowered onto the peg


def _peg(world: World) -> tuple[np.ndarray, np.ndarray]:
    """The peg's free end (world) and its axis, pointing along the peg towards the post."""
    inst = world.object("rack")
    fp = CATALOG.get(inst.type_name).functional_point("peg")
    rot = world.object_mat("rack")
    return world.object_pos("rack") + rot @ np.asarray(fp.pos), rot @ np.asarray(fp.direction)


@TASKS.register("hanging_mug")
class HangingMug(AtomicTask):
    instructions = ("hang the mug on the rack", "hang the {color} mug on the mug rack by its handle")
    items = (Item("mug", "mug", (0.45, -0.12)), Item("rack", "mug_rack", (0.63, 0.08)))
    # where the mug comes down beside the peg's end
    reserved = (ReservedZone("approach", Region((0.6, -0.06), (0.06, 0.05))),)

    def words(self) -> dict[str, str]:
        return {"color": self.color_of("mug")}

    def expert(self, skills: Skills) -> None:
        world = skills.world
        skills.do("grasp", obj="mug", grasp_name="rim_1")  # the rim opposite the handle
        skills.do("lift", height=0.2)
        # the handle points the way the rack faces, so the peg runs through its opening
        skills.do("rotate", angle=wrap_angle(heading(world, "rack") - heading(world, "mug")))
        inst = world.object("mug")
        hole = world.object_pos("mug") + world.object_mat("mug") @ (np.asarray(HOLE) * inst.scale)
        offset = hole - skills.tcp()[0]
        end, axis = _peg(world)
        skills.do("move_to", pos=end - axis * BEFORE - offset)
        skills.do("move_line", pos=end + axis * ON_PEG - offset, speed=0.05)
        skills.do("move_line", pos=end + axis * ON_PEG - offset - [0.0, 0.0, DROP], speed=0.05)
        skills.do("open_gripper")
        skills.do("move_line", pos=end + axis * ON_PEG - offset + [0.0, 0.0, 0.06])
        skills.do("retreat")

    def evaluate(self, world: World) -> dict[str, Any]:
        hanging = P.lifted(world, "mug") and P.contact_between(world, "mug", "rack")
        released = not P.grasped(world, "mug")
        rack_up = P.upright(world, "rack")
        return {"success": hanging and released and rack_up, "hanging": hanging, "released": released,
                "rack_upright": rack_up}
