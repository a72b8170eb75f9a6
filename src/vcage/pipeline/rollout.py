"""Execute a plan's subtasks in order on a world, auditing each one with the oracle.

After every subtask the command is held for a moment (success must hold on consecutive control
steps, :func:`vcage.tasks.success.held`), the oracle's verdict is recorded with the subtask's frame
boundaries, and an optional verifier (the critic) decides whether to go on. A skill that cannot
plan ends the rollout.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import partial
from typing import Any, Protocol

from vcage.errors import SkillError
from vcage.planning.schema import Plan, Subtask
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.tasks.oracle import Oracle
from vcage.tasks.success import held


@dataclass
class SubtaskOutcome:
    index: int
    skill: str
    description: str
    start: int  # first frame of the subtask in the recording
    end: int  # one past its last frame
    oracle: dict[str, bool]
    oracle_success: bool
    skill_error: str | None = None
    verdict: dict[str, Any] | None = None  # the critic's, when one judged


@dataclass
class Rollout:
    outcomes: list[SubtaskOutcome] = field(default_factory=list)
    aborted_at: int | None = None  # index of the subtask after which the verifier stopped it

    @property
    def oracle_success(self) -> bool:
        return bool(self.outcomes) and all(o.oracle_success for o in self.outcomes)


class SubtaskVerifier(Protocol):
    def start(self, index: int, subtask: Subtask) -> None: ...

    def judge(self, outcome: SubtaskOutcome) -> dict[str, Any]:
        """A verdict with a boolean ``"accept"``."""


def run_plan(world: World, plan: Plan, skills: Skills | None = None,
             verifier: SubtaskVerifier | None = None) -> Rollout:
    skills = skills or Skills(world)
    oracle = Oracle()
    skills.player.hooks.append(oracle.on_step)
    rollout = Rollout()
    for i, sub in enumerate(plan.subtasks):
        if verifier is not None:
            verifier.start(i, sub)
        oracle.begin(sub.predicates)
        start = len(skills.player.recording)
        error = None
        try:
            skills.do(sub.skill, **_skill_args(sub))
            skills.do("retreat")  # back home: the views after the subtask show it unobstructed
        except SkillError as exc:
            error = str(exc)
        values, _ = held(skills, partial(oracle.check, world, sub.predicates))
        outcome = SubtaskOutcome(i, sub.skill, sub.description, start, len(skills.player.recording),
                                 values, error is None and all(values.values()), error)
        rollout.outcomes.append(outcome)
        if error is not None:
            rollout.aborted_at = i
            break
        if verifier is not None:
            outcome.verdict = verifier.judge(outcome)
            if not outcome.verdict.get("accept", False):
                rollout.aborted_at = i
                break
    return rollout


def _skill_args(sub: Subtask) -> dict[str, Any]:
    args = dict(sub.args)
    if isinstance(args.get("xy"), list):
        args["xy"] = tuple(args["xy"])
    return args
