"""The critic's side of a rollout: render the views it needs around each subtask and ask it.

The critic sees rendered images, segmentation and depth, the subtask's description and
predicates; the oracle's values ride along only for the oracle critic. The frame "during" a
subtask is chosen from proprioception (where the hand was lowest, e.g. a press), as on a robot.
"""

from __future__ import annotations

import time
from typing import Any, Protocol

from vcage.critics.base import Critic, Observation, View
from vcage.planning.schema import Plan, Subtask
from vcage.sim.render import Renderer
from vcage.sim.world import World
from vcage.skills.playback import Recording
from vcage.subtasks.judge import deepest, render_views


class Outcome(Protocol):
    """What the verifier needs of a finished subtask (see :class:`.rollout.SubtaskOutcome`)."""

    index: int
    start: int
    end: int
    oracle: dict[str, bool]


class Timed(Protocol):
    """Where the verifier adds its seconds (see :class:`.episode.Timing`)."""

    critic_views: float  # rendering the views (and setting the state of the "during" frame)
    critic_judge: float  # the critic's judgement of them


class Verifier:
    """Asks ``critic`` about each subtask, with views rendered before, during and after it."""

    def __init__(self, world: World, plan: Plan, critic: Critic, renderer: Renderer | None,
                 recording: Recording, timing: Timed) -> None:
        self.world, self.plan, self.critic = world, plan, critic
        self.renderer, self.recording, self.timing = renderer, recording, timing
        self._before: dict[str, View] = {}
        self.rejected_views: dict[str, dict[str, View]] = {}  # moment -> views of a rejected subtask

    def _views(self) -> dict[str, View]:
        return render_views(self.renderer) if self.renderer is not None else {}

    def start(self, index: int, subtask: Subtask) -> None:
        t0 = time.perf_counter()
        self._before = self._views()
        self.timing.critic_views += time.perf_counter() - t0

    def judge(self, outcome: Outcome) -> dict[str, Any]:
        t0 = time.perf_counter()
        after = self._views()
        during = self._deepest(outcome)
        t1 = time.perf_counter()
        self.timing.critic_views += t1 - t0
        obs = Observation(subtask=self.plan.subtasks[outcome.index], labels=tuple(self.world.object_names),
                          before=self._before, after=after, during=during, oracle=outcome.oracle,
                          types={n: self.world.object(n).type_name for n in self.world.object_names})
        verdict = self.critic.judge(obs)
        self.timing.critic_judge += time.perf_counter() - t1
        if not verdict.accept:
            self.rejected_views = {"before": obs.before, "during": obs.during, "after": obs.after}
        return {**verdict.to_dict(), "critic": self.critic.version()}

    def _deepest(self, outcome: Outcome) -> dict[str, View]:
        """Views of the recorded frame where the hand was lowest during the subtask."""
        return deepest(self.world, self.renderer, self.recording, outcome.start, outcome.end,
                       self.plan.subtasks[outcome.index].skill)
