"""The words plans are written in: the success predicates and the skills a plan may call.

This is the one table of names, arities and parameters that every stage agrees on. It is core
(no MuJoCo import), so the plan schema and the LLM prompt can use it without loading a simulator.
Each predicate is implemented twice, against it: an oracle check on simulator state
(:mod:`vcage.tasks.predicates`) and an image check (:mod:`vcage.critics.image`); each plan skill
once, as a motion primitive (:mod:`vcage.skills.primitives`). Tests hold the implementations to
these signatures.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import Any

from vcage.errors import RegistryError
from vcage.registry import Registry


class Kind(StrEnum):
    """A *state* predicate must hold on the final state; an *event* must have happened during the
    subtask (a button springs back, so "pressed" is latched while the subtask runs)."""

    STATE = "state"
    EVENT = "event"


@dataclass(frozen=True)
class PredicateSpec:
    name: str
    arity: tuple[int, int]  # (minimum, maximum) number of object arguments
    kind: Kind
    meaning: str  # one sentence, as the LLM planner is told

    def check_arity(self, args: tuple[str, ...]) -> None:
        lo, hi = self.arity
        if not lo <= len(args) <= hi:
            raise ValueError(f"predicate {self.name} takes {lo}..{hi} objects, got {list(args)}")


PREDICATES: Registry[PredicateSpec] = Registry("predicate", error=RegistryError)


def _predicate(name: str, lo: int, hi: int, meaning: str, kind: Kind = Kind.STATE) -> None:
    PREDICATES.add(name, PredicateSpec(name, (lo, hi), kind, meaning))


_predicate("on", 2, 2, "the first object rests on the second's placement surface")
_predicate("inside", 2, 2, "the first object is inside the second (a container), below its rim")
_predicate("stacked", 2, 4, "each object rests on the one before it, the first at the bottom")
_predicate("near", 2, 2, "the two objects' centres are within 10 cm of each other on the table")
_predicate("left_of", 2, 2, "the first object is left of the second as seen from the robot")
_predicate("right_of", 2, 2, "the first object is right of the second as seen from the robot")
_predicate("on_table", 1, 1, "the object rests on the table top itself, not on another object")
_predicate("upright", 1, 1, "the object stands in its upright orientation (not tipped over)")
_predicate("lifted", 1, 1, "the object is held at least 5 cm above the table")
_predicate("released", 1, 1, "the hand no longer holds the object")
_predicate("pressed", 1, 1, "the robot pressed the object's button or lever during the subtask", Kind.EVENT)
_predicate("opened", 1, 1, "the object's drawer is pulled out at least as far as counts as open")
_predicate("closed", 1, 1, "the object's drawer is pushed shut")
_predicate("hanging", 2, 2, "the first object hangs from the second (on its hook), clear of the table")
_predicate("facing", 1, 1, "the object's functional face (a board's code, a fan's front) points at the robot")


@dataclass(frozen=True)
class Param:
    name: str
    required: bool = True
    default: Any = None
    names_object: bool = False  # the value is the name of an object of the plan


@dataclass(frozen=True)
class SkillSpec:
    """A skill a plan may call: its parameters (without the world) and what it does."""

    name: str
    params: tuple[Param, ...]
    doc: str

    def check_args(self, args: dict[str, Any]) -> None:
        names = [p.name for p in self.params]
        extra = set(args) - set(names)
        if extra:
            raise ValueError(f"skill {self.name} has no argument(s) {sorted(extra)}; it takes {names}")
        missing = [p.name for p in self.params if p.required and p.name not in args]
        if missing:
            raise ValueError(f"skill {self.name} needs argument(s) {missing}")

    def signature(self) -> str:
        return ", ".join(p.name if p.required else f"{p.name}={p.default!r}" for p in self.params)

    def object_args(self, args: dict[str, Any]) -> list[str]:
        return [args[p.name] for p in self.params if p.names_object and isinstance(args.get(p.name), str)]


PLAN_SKILLS: Registry[SkillSpec] = Registry("plan skill", error=RegistryError)


def _obj(name: str, required: bool = True) -> Param:
    return Param(name, required, None, names_object=True)


def _opt(name: str, default: Any = None) -> Param:
    return Param(name, False, default)


def _skill(name: str, doc: str, *params: Param) -> None:
    PLAN_SKILLS.add(name, SkillSpec(name, params, doc))


# The composite skills a planner needs; the building blocks (move_to, place, ...) are not offered.
_skill("pick_and_place", "Grasp, lift, place and withdraw, planned open loop from the current state.",
       _obj("obj"), _obj("target", False), _opt("placement"), _opt("xy"), _opt("grasp_name"))
_skill("press", "Press ``obj``'s functional point down by its stroke plus ``depth`` with the closed hand.",
       _obj("obj"), _opt("point"), _opt("depth", 0.004), _opt("hold", 0.3))
_skill("push", "Slide ``obj`` along ``direction`` by ``distance`` with the closed fingers, low over the "
       "table.", _obj("obj"), Param("direction"), Param("distance"), _opt("height", 0.012))
_skill("lift", "Raise the hand (and whatever it holds) straight up to ``height`` above the table.",
       _opt("height", 0.12))
_skill("grasp", "Approach ``obj`` from above along its best reachable grasp annotation and close the "
       "hand.", _obj("obj"), _opt("grasp_name"))
_skill("retreat", "Move up to the safe height, then (optionally) back to the home posture.",
       _opt("home", True))
_skill("open_gripper", "Open the hand fully where it is.")
_skill("open_drawer", "Pull ``obj``'s drawer out by its handle to ``distance`` metres (default: the "
       "handle's stroke).", _obj("obj"), _opt("point"), _opt("distance"))
_skill("close_drawer", "Push ``obj``'s drawer shut by its handle.", _obj("obj"), _opt("point"))
_skill("hang", "Hang ``obj`` by its loop (a mug's handle) on ``target``'s hook (a rack's peg).",
       _obj("obj"), _obj("target"), _opt("point"))
_skill("turn_to_face", "Grasp, lift and put down ``obj`` turned so that its face points at the robot.",
       _obj("obj"), _obj("target", False), _opt("placement"), _opt("xy"), _opt("point"), _opt("grasp_name"))
