"""The episode engine: the one loop of expert episodes (steps, holds, verifier) and a policy's
progress through goals, on a real MuJoCo world."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import pytest

from vcage.errors import SkillError
from vcage.planning.schema import Predicate
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.skills.playback import Player
from vcage.tasks.engine import PredicateGoal, Progress, Step, StepOutcome, run
from vcage.tasks.oracle import Oracle

HOLD = 3


@dataclass
class Scripted:
    """A goal whose value at each check comes from ``values`` (then stays at its last); counts the
    control steps it was told of and whether it began."""

    values: list[bool]
    hold_steps: int = HOLD
    checks: int = 0
    steps: int = 0
    began: int = 0

    def begin(self) -> None:
        self.began += 1

    def on_step(self, world: World) -> None:
        self.steps += 1

    def check(self) -> dict[str, Any]:
        value = self.values[min(self.checks, len(self.values) - 1)]
        self.checks += 1
        return {"met": value}

    def reached(self, values: dict[str, Any]) -> bool:
        return bool(values["met"])


@dataclass
class Judge:
    """A verifier that rejects the steps in ``reject``; records what it was asked."""

    reject: set[int] = field(default_factory=set)
    started: list[int] = field(default_factory=list)
    judged: list[int] = field(default_factory=list)

    def start(self, index: int) -> None:
        self.started.append(index)

    def judge(self, outcome: StepOutcome) -> dict[str, Any]:
        self.judged.append(outcome.index)
        return {"accept": outcome.index not in self.reject, "reason": "scripted"}


def wait(seconds: float) -> Any:
    def act(skills: Skills) -> None:
        skills.player.wait(seconds)
    return act


def fail(skills: Skills) -> None:
    skills.player.wait(0.1)
    raise SkillError("no grasp found")


def step(goal: Scripted, act: Any = None) -> Step:
    return Step("wait", "wait a moment", act or wait(0.1), goal)


def test_steps_run_in_order_each_held_and_judged(world: World) -> None:
    skills = Skills(world, Player(world))
    goals = [Scripted([True]), Scripted([False] * HOLD + [True])]
    rollout = run(skills, [step(goals[0]), step(goals[1])])
    first, second = rollout.outcomes
    assert rollout.aborted_at is None and [o.index for o in rollout.outcomes] == [0, 1]
    assert first.oracle_success and first.oracle == {"met": True}
    # the hold keeps the command for 2 * HOLD control steps: met on the last HOLD of them counts
    assert second.oracle_success and goals[1].checks == 2 * HOLD
    assert second.start == first.end and len(skills.player.recording) == second.end
    # each goal is told of the control steps of its own step only (its act and its hold)
    assert goals[0].steps == first.end - first.start and goals[1].steps == second.end - second.start
    assert goals[0].began == goals[1].began == 1
    assert not rollout.oracle_success or all(o.oracle_success for o in rollout.outcomes)


def test_goals_stop_watching_when_the_program_ends(world: World) -> None:
    skills = Skills(world, Player(world))
    goal = Scripted([True])
    run(skills, [step(goal)])
    told = goal.steps
    skills.player.wait(0.1)  # the skills act on after the program (e.g. another program)
    assert goal.steps == told and skills.player.hooks == []


def test_a_goal_met_too_late_in_the_hold_is_not_reached(world: World) -> None:
    goal = Scripted([False] * (HOLD + 1) + [True])
    rollout = run(Skills(world, Player(world)), [step(goal)])
    assert not rollout.outcomes[0].oracle_success and not rollout.oracle_success
    assert rollout.aborted_at is None  # an unmet goal without a verifier does not stop the program


def test_a_skill_error_ends_the_program_after_its_hold(world: World) -> None:
    skills = Skills(world, Player(world))
    goals = [Scripted([True]), Scripted([True])]
    judge = Judge()
    rollout = run(skills, [step(goals[0], fail), step(goals[1])], judge)
    (only,) = rollout.outcomes
    assert only.skill_error == "no grasp found" and rollout.aborted_at == 0
    assert not only.oracle_success  # the goal held, but the step did not do its work
    assert goals[0].checks == 2 * HOLD and goals[1].began == 0
    assert judge.judged == []  # a step that could not plan is not shown to the critic


def test_the_verifier_stops_the_program_at_its_first_rejection(world: World) -> None:
    goals = [Scripted([True]) for _ in range(3)]
    judge = Judge(reject={1})
    rollout = run(Skills(world, Player(world)), [step(g) for g in goals], judge)
    assert rollout.aborted_at == 1 and len(rollout.outcomes) == 2
    assert judge.started == [0, 1] and judge.judged == [0, 1] and goals[2].began == 0
    assert rollout.outcomes[1].verdict == {"accept": False, "reason": "scripted"}


def test_judge_unmet_false_asks_the_verifier_only_about_reached_goals(world: World) -> None:
    goals = [Scripted([False]), Scripted([True])]
    judge = Judge(reject={0, 1})
    rollout = run(Skills(world, Player(world)), [step(g) for g in goals], judge, judge_unmet=False)
    assert judge.judged == [1] and rollout.outcomes[0].verdict is None
    assert rollout.aborted_at == 1
    judge = Judge(reject={0})
    rollout = run(Skills(world, Player(world)), [step(Scripted([False])), step(Scripted([True]))], judge)
    assert judge.judged == [0] and rollout.aborted_at == 0  # by default the critic judges every step


def test_progress_reaches_goals_in_order_on_consecutive_steps(world: World) -> None:
    goals = [Scripted([True, True, False, True, True, True]), Scripted([True])]
    progress = Progress(goals)
    assert goals[0].began == 1 and goals[1].began == 0
    for _ in range(5):  # true, true, false (the streak restarts), true, true
        progress.update(world)
    assert progress.done == 0 and progress.streak == 2
    progress.update(world)
    assert progress.done == 1 and goals[1].began == 1 and goals[0].steps == 6
    for _ in range(HOLD):
        progress.update(world)
    assert progress.finished and progress.update(world) == {}
    assert goals[1].steps == HOLD  # not told of a step once finished


def test_progress_can_start_at_a_later_goal(world: World) -> None:
    goals = [Scripted([True]), Scripted([True])]
    progress = Progress(goals, start=1)
    assert progress.done == 1 and goals[0].began == 0 and goals[1].began == 1
    with pytest.raises(ValueError, match="not a goal index"):
        Progress(goals, start=2)


def test_a_predicate_goal_latches_its_events_from_begin(world: World) -> None:
    oracle = Oracle()
    pressed = PredicateGoal(oracle, world, (Predicate(name="pressed", args=["a"]),))
    assert pressed.check() == {"pressed(a)": False}  # not watched: an event cannot have happened
    pressed.begin()
    assert list(oracle.latches) == [Predicate(name="pressed", args=["a"])]
    assert not pressed.reached(pressed.check())
