"""Scripted use of a cabinet's drawer: take its handle, slide it to an opening, let go."""

from __future__ import annotations

import math

import numpy as np

from vcage.skills.base import Skills
from vcage.tasks.library._support import functional_pos, heading

ABOVE = 0.08  # the hand comes down onto the handle from this far above it
AJAR = 0.4  # gripper opening around the handle: the finger behind it must fit in front of the drawer


def slide_drawer(skills: Skills, cabinet: str, opening: float) -> None:
    """Grasp the handle of ``cabinet``'s drawer, slide the drawer until it is ``opening`` metres out
    (0: shut; a little past it, the joint's limit stops the drawer), release and move up."""
    world = skills.world
    handle = functional_pos(world, cabinet)
    yaw = skills.natural_yaw(heading(world, cabinet) + math.pi / 2)  # fingers close along the pull
    out = world.object_mat(cabinet) @ np.array([-1.0, 0.0, 0.0])  # the drawer's way out
    now = -world.joint_value(f"{cabinet}/drawer")
    skills.do("move_to", pos=handle + [0.0, 0.0, ABOVE], yaw=yaw, gripper=AJAR)
    skills.do("move_line", pos=handle)
    skills.do("close_gripper")
    skills.do("move_line", pos=handle + out * (opening - now), speed=0.08)
    skills.do("open_gripper")
    skills.do("move_line", pos=handle + out * (opening - now) + [0.0, 0.0, ABOVE])
