"""A task's nominal items and the :class:`LayoutSpec` they make under seeded randomisation.

The layout goes through scene instantiation (context-aware placement by default), so randomised
poses never interpenetrate and clutter can be added around the task's objects.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from vcage.config import Randomization
from vcage.scene.layout import Distractors, LayoutObject, LayoutSpec, Region, Relation, ReservedZone
from vcage.scene.randomize import environment, object_look


@dataclass(frozen=True)
class Item:
    """A task object at its nominal pose; ``colors`` restricts the variants it may take."""

    name: str
    type: str
    xy: tuple[float, float]
    yaw: float = 0.0
    colors: tuple[str, ...] | None = None
    jitter: bool = True  # False pins the pose (still scaled/coloured when randomised)


def task_layout(items: Sequence[Item], rng: np.random.Generator, rand: Randomization,
                relations: Sequence[Relation] = (), reserved: Sequence[ReservedZone] = (),
                clutter: int = 0) -> LayoutSpec:
    """The layout of ``items``: nominal poses when ``rand.enabled`` is False; otherwise each
    item's origin may go anywhere in its jitter box and its yaw anywhere in its jitter range, and
    scale, colour, friction, table, light and cameras are drawn from ``rng``."""
    objects = []
    for item in items:
        if not rand.enabled or not item.jitter:
            region, yaw = Region(item.xy), (item.yaw, item.yaw)
        else:
            lo, hi = rand.object_xy.low, rand.object_xy.high
            mid = (lo + hi) / 2
            region = Region((item.xy[0] + mid, item.xy[1] + mid), ((hi - lo) / 2, (hi - lo) / 2))
            yaw = (item.yaw + rand.object_yaw.low, item.yaw + rand.object_yaw.high)
        scale, color, friction = object_look(item.type, rng, rand, item.colors)
        objects.append(LayoutObject(item.name, item.type, region=region, yaw=yaw, scale=scale,
                                    color=color, friction=friction))
    return LayoutSpec(objects=tuple(objects), relations=tuple(relations), reserved=tuple(reserved),
                      distractors=Distractors(clutter), **environment(rng, rand))
