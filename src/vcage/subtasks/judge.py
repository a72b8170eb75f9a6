"""The critic's part of a trial: the views before, during and after the subtask, and its verdict.

The same views the pipeline's verifier gives a critic (``pipeline.verifier``: top and front RGB
with segmentation and depth; the "during" frame where the hand was lowest in the subtask's own
skill), built here because this layer sits below the pipeline. The critic sees views and the
subtask's text and predicates, never the simulator; the oracle's values ride along for the oracle
critic only.
"""

from __future__ import annotations

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


def judge(critic: Critic, subtask: Subtask, world: World, before: dict[str, View], during: dict[str, View],
          after: dict[str, View], oracle: dict[str, bool]) -> Verdict:
    types = {n: world.object(n).type_name for n in world.object_names}
    obs = Observation(subtask=subtask, labels=tuple(world.object_names), before=before, after=after,
                      during=during, oracle=oracle, types=types)
    return critic.judge(obs)
