"""The episode engine: a program of steps run by the scripted skills, each judged by its goal.

Every expert episode is run here: an atomic task (one step: the task's expert, judged by the task's
success), a plan's rollout (a step per subtask: its skill call and a retreat, judged by the oracle
on the subtask's predicates) and a subtask trial (one step: the candidate's skill calls). A step
acts; a skill that cannot plan ends the program. Then the last command is held and the goal must
hold on consecutive control steps (:func:`~vcage.tasks.success.held`); an optional verifier (the
critic) judges the step and may stop the program.

A policy's episode is stepped from outside, one control step at a time (the Gymnasium
environments): :class:`Progress` judges it with the same goals, in order, each reached once it held
for its hold steps.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

from vcage.errors import SkillError
from vcage.planning.schema import Predicate
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.tasks.base import AtomicTask
from vcage.tasks.oracle import Oracle
from vcage.tasks.success import HOLD_STEPS


class Goal(Protocol):
    """What a step must achieve: watched from :meth:`begin`, told of every control step, checked."""

    @property
    def hold_steps(self) -> int:
        """Consecutive control steps the goal must hold."""

    def begin(self) -> None: ...

    def on_step(self, world: World) -> None: ...

    def check(self) -> dict[str, Any]:
        """The goal's values now (true values are met)."""

    def reached(self, values: dict[str, Any]) -> bool:
        """Whether ``values`` (of :meth:`check`, or whether each held) mean the goal is met."""


@dataclass
class PredicateGoal:
    """A subtask's predicates, read by ``oracle`` (shared by the subtasks of one episode)."""

    oracle: Oracle
    world: World
    predicates: tuple[Predicate, ...]
    hold_steps: int = HOLD_STEPS

    def begin(self) -> None:
        self.oracle.begin(self.predicates)

    def on_step(self, world: World) -> None:
        self.oracle.on_step(world)

    def check(self) -> dict[str, Any]:
        return dict(self.oracle.check(self.world, self.predicates))

    def reached(self, values: dict[str, Any]) -> bool:
        return all(values.values())


@dataclass
class TaskGoal:
    """An atomic task's success (``task.evaluate``: ``success`` and what it measured beside)."""

    task: AtomicTask
    world: World

    @property
    def hold_steps(self) -> int:
        return self.task.hold_steps

    def begin(self) -> None:
        pass

    def on_step(self, world: World) -> None:
        self.task.on_step(world)

    def check(self) -> dict[str, Any]:
        return dict(self.task.evaluate(self.world))

    def reached(self, values: dict[str, Any]) -> bool:
        return bool(values["success"])


@dataclass(frozen=True)
class Step:
    """One step of a program: what it does with the skills, and the goal that judges it."""

    skill: str  # the skill doing the step's work (an atomic task's expert: the task's name)
    description: str
    act: Callable[[Skills], None]
    goal: Goal


@dataclass
class StepOutcome:
    index: int
    skill: str
    description: str
    start: int  # first frame of the step in the recording
    end: int  # one past its last frame (the hold included)
    oracle: dict[str, bool]  # whether each of the goal's values held
    oracle_success: bool  # no skill error and the goal reached
    skill_error: str | None = None
    verdict: dict[str, Any] | None = None  # the verifier's, when one judged
    values: dict[str, Any] = field(default_factory=dict)  # the goal's values at the end of the hold


@dataclass
class Rollout:
    outcomes: list[StepOutcome] = field(default_factory=list)
    aborted_at: int | None = None  # index of the step after which the program stopped

    @property
    def oracle_success(self) -> bool:
        return bool(self.outcomes) and all(o.oracle_success for o in self.outcomes)


class StepVerifier(Protocol):
    def start(self, index: int) -> None:
        """Step ``index`` is about to act (e.g. render the views before it)."""

    def judge(self, outcome: StepOutcome) -> dict[str, Any]:
        """A verdict with a boolean ``"accept"``."""


def run(skills: Skills, steps: Sequence[Step], verifier: StepVerifier | None = None, *,
        judge_unmet: bool = True) -> Rollout:
    """Run ``steps`` in order on ``skills``' world: the one loop every expert episode goes through.

    A step whose skill raises :class:`SkillError` is still held and judged by its goal, then ends the
    program. ``verifier`` judges each step that ran (with ``judge_unmet`` False only those whose goal
    was reached: a trial asks its critic only then) and stops the program at its first rejection. A
    :class:`SimulationError` propagates: an unstable rollout is not an outcome.
    """
    current: list[Goal] = []

    def on_step(world: World) -> None:  # the current step's goal is told of every control step
        if current:
            current[0].on_step(world)

    skills.player.hooks.append(on_step)
    try:
        return _run(skills, steps, verifier, judge_unmet, current)
    finally:  # the skills may act on after the program: its goals no longer watch
        skills.player.hooks.remove(on_step)


def _run(skills: Skills, steps: Sequence[Step], verifier: StepVerifier | None, judge_unmet: bool,
         current: list[Goal]) -> Rollout:
    recording = skills.player.recording
    rollout = Rollout()
    for i, step in enumerate(steps):
        if verifier is not None:
            verifier.start(i)
        current[:] = [step.goal]
        step.goal.begin()
        start = len(recording)
        error = None
        try:
            step.act(skills)
        except SkillError as exc:
            error = str(exc)
        holds, values = held(skills, step.goal.check, step.goal.hold_steps)
        outcome = StepOutcome(i, step.skill, step.description, start, len(recording), holds,
                              error is None and step.goal.reached(holds), error, values=values)
        rollout.outcomes.append(outcome)
        if error is not None:
            rollout.aborted_at = i
            break
        if verifier is not None and (judge_unmet or outcome.oracle_success):
            outcome.verdict = verifier.judge(outcome)
            if not outcome.verdict.get("accept", False):
                rollout.aborted_at = i
                break
    return rollout


def held(skills: Skills, check: Callable[[], dict[str, Any]],
         steps: int = HOLD_STEPS) -> tuple[dict[str, bool], dict[str, Any]]:
    """Keep the last command for ``2 * steps`` control steps, calling ``check`` after each.

    Returns, per key of ``check``'s dict, whether its value was true on the last ``steps``
    consecutive calls, and the last dict itself.
    """
    streak: dict[str, int] = {}
    values: dict[str, Any] = {}
    for _ in range(steps * 2):
        skills.player.wait(skills.world.control_dt)
        values = check()
        streak = {k: streak.get(k, 0) + 1 if v else 0 for k, v in values.items()}
    return {k: streak[k] >= steps for k in values}, values


class Progress:
    """A policy's episode judged by ``goals`` in order, one control step at a time.

    After each control step call :meth:`update`: the current goal is told of the step and checked;
    once it is met on ``hold_steps`` consecutive steps the next one begins. ``done`` counts the goals
    reached; the episode succeeds when all are.
    """

    def __init__(self, goals: Iterable[Goal], start: int = 0) -> None:
        self.goals = tuple(goals)
        if not 0 <= start < len(self.goals):
            raise ValueError(f"start {start} is not a goal index (there are {len(self.goals)})")
        self.done, self.streak = start, 0
        self.goals[start].begin()

    @property
    def finished(self) -> bool:
        return self.done == len(self.goals)

    def update(self, world: World) -> dict[str, Any]:
        """Judge the control step just taken; returns the current goal's values (empty once finished)."""
        if self.finished:
            return {}
        goal = self.goals[self.done]
        goal.on_step(world)
        values = goal.check()
        self.streak = self.streak + 1 if goal.reached(values) else 0
        if self.streak >= goal.hold_steps:
            self.done, self.streak = self.done + 1, 0
            if not self.finished:
                self.goals[self.done].begin()
        return values
