"""Real failed rollouts for critic tests: a small scene, one subtask, a fault injected into its skill;
or one of Vanilla's episodes of a benchmark goal, as ``benchmarks/critic_agreement.py`` rolls it out.

The subtask runs in MuJoCo through the pipeline's own rollout and verifier (views rendered before,
during and after it); nothing is teleported. Returns what the critic saw and the oracle's values.
"""

from __future__ import annotations

from dataclasses import dataclass

from vcage.critics.base import Observation, Recorder
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.episode import Timing, attempt
from vcage.pipeline.rollout import SubtaskOutcome, run_plan
from vcage.pipeline.verifier import Verifier
from vcage.planning import make_planner
from vcage.planning.goals import GOALS
from vcage.planning.schema import Plan, PlanObject, Subtask
from vcage.scene.compose import compose
from vcage.scene.spec import ObjectSpec, SceneSpec
from vcage.sim.render import Renderer
from vcage.skills.base import Skills
from vcage.skills.faults import FaultConfig, FaultInjector
from vcage.skills.playback import Player


@dataclass
class Run:
    obs: Observation
    outcome: SubtaskOutcome
    applied: bool  # whether the fault was injected

    @property
    def success(self) -> bool:
        return self.outcome.oracle_success


def run(objects: tuple[ObjectSpec, ...], subtask: Subtask, fault: str | None = None, seed: int = 0,
        before: tuple[Subtask, ...] = ()) -> Run:
    """Execute ``subtask`` in a scene of ``objects`` with ``fault`` injected into its skill, after the
    subtasks ``before`` (done as planned; their skills must differ from its own)."""
    world = compose(SceneSpec(objects=objects)).make_world()
    world.settle(0.3)
    plan = Plan(instruction="test", objects=tuple(PlanObject(name=o.name, type=o.type) for o in objects),
                subtasks=(*before, subtask))
    assert all(st.skill != subtask.skill for st in before)
    injector = FaultInjector(FaultConfig(fault, subtask.skill, 0, seed)) if fault else None
    skills = Skills(world, Player(world, record_states=True), fault=injector)
    keep = Recorder()
    with Renderer(world, 320, 240) as renderer:
        verifier = Verifier(world, plan, keep, renderer, skills.player.recording, Timing())
        rollout = run_plan(world, plan, skills, verifier)
    outcome = rollout.outcomes[-1]
    assert len(rollout.outcomes) == len(plan.subtasks) and outcome.skill_error is None, outcome.skill_error
    assert all(o.oracle_success for o in rollout.outcomes[:-1]), rollout.outcomes
    return Run(keep.seen[-1], outcome, injector is None or injector.applied)


def vanilla(goal: str, episode: int) -> list[tuple[Observation, SubtaskOutcome]]:
    """What the critic was shown of each judged subtask of Vanilla's episode ``episode`` of ``goal``
    (naive placement and no scene check: the plan's objects may start fused into one another), and
    the subtask's outcome; the rollout goes on whatever the critic says."""
    plan = make_planner("offline").plan(next(g for g in GOALS if g.name == goal).phrasings[0])
    cfg = GenerateConfig.vanilla(seed=0)
    keep = Recorder()
    result = attempt(plan, cfg.episode_seed(episode, 0), cfg, keep)
    assert result.rollout is not None, result
    judged = [o for o in result.rollout.outcomes if o.verdict is not None]
    return list(zip(keep.seen, judged, strict=True))
