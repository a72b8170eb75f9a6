"""Stack one block on another."""

from __future__ import annotations

from vcage.planning.schema import Predicate
from vcage.skills.base import Skills
from vcage.tasks.base import TASKS, AtomicTask, Item, pred


@TASKS.register("stack_blocks_two")
class StackBlocksTwo(AtomicTask):
    instructions = (
        "stack the {top} block on the {bottom} block",
        "put the {top} block on top of the {bottom} one",
        "place the {top} cube onto the {bottom} cube",
    )
    items = (
        Item("block_a", "block", (0.5, -0.12), colors=("red", "orange", "yellow")),
        Item("block_b", "block", (0.52, 0.12), colors=("blue", "green", "purple")),
    )

    def words(self) -> dict[str, str]:
        return {"top": self.color_of("block_a"), "bottom": self.color_of("block_b")}

    def expert(self, skills: Skills) -> None:
        skills.do("pick_and_place", obj="block_a", target="block_b")
        skills.do("retreat")

    def success(self) -> tuple[Predicate, ...]:
        return pred("stacked", "block_b", "block_a"), pred("released", "block_a")
