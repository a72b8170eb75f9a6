"""The critic's side of an episode: the views it needs around each step, and its verdict.

The critic sees rendered images (top and front RGB with segmentation and depth), the subtask's
description and predicates; the oracle's values ride along only for the oracle critic. It never
sees the simulator. The frame "during" a subtask is chosen from proprioception (where the hand was
lowest within the subtask's own skill, e.g. a press), as on a robot. Generation's rollouts and
subtask trials ask the critic through the same :class:`Verifier`.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from vcage.critics.base import Critic, Observation, View
from vcage.planning.schema import Subtask
from vcage.sim.render import Renderer
from vcage.sim.world import World
from vcage.skills.playback import Recording

CRITIC_CAMERAS = ("top", "front")  # the views a critic gets: top-down (orthographic) and front
DEPTH_CAMERAS = ("top", "front")  # ... with depth (the top view's: heights, for how deep a press went)


def render_views(renderer: Renderer, cameras: tuple[str, ...] = CRITIC_CAMERAS,
                 depth_cameras: tuple[str, ...] = DEPTH_CAMERAS) -> dict[str, View]:
    """The critic's views of the world as it is now."""
    return {cam: View(renderer.rgb(cam), renderer.segmentation(cam),
                      renderer.depth(cam) if cam in depth_cameras else None, renderer.pixel_size(cam),
                      renderer.robot_pixel(cam))
            for cam in cameras}


def views(renderer: Renderer | None) -> dict[str, View]:
    return render_views(renderer) if renderer is not None else {}


def deepest(world: World, renderer: Renderer | None, rec: Recording, start: int, end: int,
            skill: str | None = None) -> dict[str, View]:
    """Views of the recorded frame in ``[start, end)`` where the hand was lowest (e.g. a press):
    within the motions of ``skill`` (the subtask's own, as the recording names what ran) when the
    recording holds any there, else over the whole range. What ran after the subtask's own motion
    (a retreat, or a sweep that knocked something over) may go lower without hiding its moment."""
    if renderer is None or end <= start or not rec.states:
        return {}
    frames = [i for name, a, b in rec.skills if skill is not None and name == skill
              for i in range(max(a, start), min(b, end))] or list(range(start, end))
    frame = min(frames, key=lambda i: rec.ee_pos[i][2])  # the first of equal lows, as argmin
    now = world.get_state()
    world.set_state(rec.states[frame])
    try:
        return views(renderer)
    finally:
        world.set_state(now)


class Outcome(Protocol):
    """What the verifier needs of a finished step (see :class:`.engine.StepOutcome`)."""

    index: int
    start: int
    end: int
    oracle: dict[str, bool]


class Timed(Protocol):
    """Where the verifier adds its seconds (see :class:`vcage.pipeline.episode.Timing`)."""

    critic_views: float  # rendering the views (and setting the state of the "during" frame)
    critic_judge: float  # the critic's judgement of them


@dataclass
class _Untimed:
    critic_views: float = 0.0
    critic_judge: float = 0.0


class Verifier:
    """Asks ``critic`` about each step (step ``i`` does ``subtasks[i]``), with views rendered before,
    during and after it; a :class:`~vcage.tasks.engine.StepVerifier`."""

    def __init__(self, world: World, subtasks: Sequence[Subtask], critic: Critic, renderer: Renderer | None,
                 recording: Recording, timing: Timed | None = None) -> None:
        self.world, self.subtasks, self.critic = world, tuple(subtasks), critic
        self.renderer, self.recording = renderer, recording
        self.timing: Timed = timing if timing is not None else _Untimed()
        self._before: dict[str, View] = {}
        self.rejected_views: dict[str, dict[str, View]] = {}  # moment -> views of a rejected step

    def start(self, index: int) -> None:
        t0 = time.perf_counter()
        self._before = views(self.renderer)
        self.timing.critic_views += time.perf_counter() - t0

    def judge(self, outcome: Outcome) -> dict[str, Any]:
        """The critic's verdict as a dict, with the critic's version under ``"critic"``."""
        t0 = time.perf_counter()
        after = views(self.renderer)
        subtask = self.subtasks[outcome.index]
        during = deepest(self.world, self.renderer, self.recording, outcome.start, outcome.end, subtask.skill)
        t1 = time.perf_counter()
        self.timing.critic_views += t1 - t0
        obs = Observation(subtask=subtask, labels=tuple(self.world.object_names),
                          before=self._before, after=after, during=during, oracle=outcome.oracle,
                          types={n: self.world.object(n).type_name for n in self.world.object_names})
        verdict = self.critic.judge(obs)
        self.timing.critic_judge += time.perf_counter() - t1
        if not verdict.accept:
            self.rejected_views = {"before": obs.before, "during": obs.during, "after": obs.after}
        return {**verdict.to_dict(), "critic": self.critic.version()}
