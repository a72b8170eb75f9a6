"""A plan as a program for the episode engine: a step per subtask, judged by the oracle.

Each subtask's step calls its skill and then retreats (so the views after it show the scene
unobstructed); the oracle, shared by the steps so that events latch while their subtask is the
current one, judges its predicates on consecutive control steps (:func:`vcage.tasks.engine.run`
holds); an optional verifier (the critic) decides whether to go on. A skill that cannot plan ends
the rollout.
"""

from __future__ import annotations

from collections.abc import Callable

from vcage.planning.schema import Plan, Subtask
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.tasks.engine import PredicateGoal, Rollout, Step, StepVerifier, run
from vcage.tasks.oracle import Oracle

__all__ = ["Rollout", "plan_goals", "plan_steps", "run_plan"]


def plan_goals(world: World, plan: Plan, oracle: Oracle) -> list[PredicateGoal]:
    """Each subtask's goal: its predicates, read by ``oracle`` (one per episode, so that events latch
    while their subtask is the current one). The expert's steps and a policy's progress share them."""
    return [PredicateGoal(oracle, world, tuple(sub.predicates)) for sub in plan.subtasks]


def plan_steps(world: World, plan: Plan) -> list[Step]:
    """The engine's steps of ``plan`` on ``world``: each subtask's skill call, then a retreat."""
    return [Step(sub.skill, sub.description, _acts(sub), goal)
            for sub, goal in zip(plan.subtasks, plan_goals(world, plan, Oracle()), strict=True)]


def run_plan(world: World, plan: Plan, skills: Skills | None = None,
             verifier: StepVerifier | None = None) -> Rollout:
    """Execute ``plan``'s subtasks in order on ``world`` (see the module's help)."""
    return run(skills or Skills(world), plan_steps(world, plan), verifier)


def _acts(sub: Subtask) -> Callable[[Skills], None]:
    args = dict(sub.args)
    if isinstance(args.get("xy"), list):
        args["xy"] = tuple(args["xy"])

    def act(skills: Skills) -> None:
        skills.do(sub.skill, **args)
        skills.do("retreat")  # back home: the views after the subtask show it unobstructed
    return act
