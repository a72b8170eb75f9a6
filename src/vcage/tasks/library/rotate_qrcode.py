"""Turn the QR-code board so that its code faces the robot."""

from __future__ import annotations

import math
from typing import Any

from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.tasks import predicates as P
from vcage.tasks.base import TASKS, AtomicTask, Item


@TASKS.register("rotate_qrcode")
class RotateQrcode(AtomicTask):
    instructions = ("rotate the QR code to face the robot", "turn the {color} QR code board towards me")
    items = (Item("board", "qr_board", (0.55, 0.0), yaw=math.pi / 2),)

    def words(self) -> dict[str, str]:
        return {"color": self.color_of("board")}

    def expert(self, skills: Skills) -> None:
        skills.do("turn_to_face", obj="board")  # put back where it stood
        skills.do("retreat")

    def evaluate(self, world: World) -> dict[str, Any]:
        facing = P.facing(world, "board")
        standing = P.on_table(world, "board") and P.upright(world, "board")
        released = not P.grasped(world, "board")
        return {"success": facing and standing and released, "facing": facing, "standing": standing,
                "released": released}
