"""The critic's part of a trial: the views before, during and after the subtask, and its verdict.

The same views the pipeline's verifier gives a critic (``pipeline.verifier``: top and front RGB
with segmentation, depth for the front camera; the "during" frame where the hand was lowest), built
here because this layer sits below the pipeline. The critic sees views and the subtask's text and
predicates, never the simulator; the oracle's values ride along for the oracle critic only.
"""

from __future__ import annotations

import numpy as np

from vcage.critics.base import Critic, Observation, Verdict, View
from vcage.planning.schema import Subtask
from vcage.sim.render import Renderer
from vcage.sim.world import World
from vcage.skills.playback import Recording

CRITIC_CAMERAS = ("top", "front")  # the views a critic gets: top-down (orthographic) and front
DEPTH_CAMERAS = ("top", "front")  # ... with depth (the top view's: heights, for how deep a press went)


def render_views(renderer: Renderer, cameras: tuple[str, ...] = CRITIC_CAMERAS,
                 depth_cameras: tuple[str, ...] = DEPTH_CAMERAS) -> dict[str, View]:
    """The critic's views of the world as it is now (the pipeline's verifier renders the same)."""
    return {cam: View(renderer.rgb(cam), renderer.segmentation(cam),
                      renderer.depth(cam) if cam in depth_cameras else None, renderer.pixel_size(cam))
            for cam in cameras}


def views(renderer: Renderer | None) -> dict[str, View]:
    return render_views(renderer) if renderer is not None else {}


def deepest(world: World, renderer: Renderer | None, rec: Recording, start: int, end: int) -> dict[str, View]:
    """Views of the recorded frame in ``[start, end)`` where the hand was lowest (e.g. a press)."""
    if renderer is None or end <= start or not rec.states:
        return {}
    frame = start + int(np.argmin([p[2] for p in rec.ee_pos[start:end]]))
    now = world.get_state()
    world.set_state(rec.states[frame])
    try:
        return views(renderer)
    finally:
        world.set_state(now)


def judge(critic: Critic, subtask: Subtask, world: World, before: dict[str, View], during: dict[str, View],
          after: dict[str, View], oracle: dict[str, bool]) -> Verdict:
    types = {n: world.object(n).type_name for n in world.object_names}
    obs = Observation(subtask=subtask, labels=tuple(world.object_names), before=before, after=after,
                      during=during, oracle=oracle, types=types)
    return critic.judge(obs)
