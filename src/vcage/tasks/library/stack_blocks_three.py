"""Stack three blocks into a tower."""

from __future__ import annotations

from vcage.planning.schema import Predicate
from vcage.skills.base import Skills
from vcage.tasks.base import TASKS, AtomicTask, Item, pred


@TASKS.register("stack_blocks_three")
class StackBlocksThree(AtomicTask):
    instructions = (
        "stack the {middle} block on the {bottom} block, then the {top} block on top",
        "build a tower: {bottom} at the bottom, {middle} in the middle, {top} on top",
    )
    items = (
        Item("block_a", "block", (0.45, -0.15), colors=("red",)),
        Item("block_b", "block", (0.58, -0.02), colors=("green",)),
        Item("block_c", "block", (0.48, 0.15), colors=("blue",)),
    )

    def words(self) -> dict[str, str]:
        return {"bottom": self.color_of("block_b"), "middle": self.color_of("block_a"),
                "top": self.color_of("block_c")}

    def expert(self, skills: Skills) -> None:
        skills.do("pick_and_place", obj="block_a", target="block_b")
        skills.do("pick_and_place", obj="block_c", target="block_a")
        skills.do("retreat")

    def success(self) -> tuple[Predicate, ...]:
        return pred("stacked", "block_b", "block_a", "block_c"), pred("released", "block_c")
