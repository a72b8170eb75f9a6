"""Seeded domain randomisation of a task's nominal layout into a :class:`SceneSpec`."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from vcage.assets.catalog import CATALOG
from vcage.config import Randomization, Range
from vcage.scene.spec import ObjectSpec, SceneSpec, TableSpec

TABLE_COLORS = ((0.62, 0.47, 0.33, 1.0), (0.75, 0.75, 0.72, 1.0), (0.35, 0.28, 0.22, 1.0),
                (0.55, 0.6, 0.65, 1.0))
TABLE_TEXTURES = ("plain", "checker", "grid")
NOMINAL_TABLE_HEIGHT = 0.75
NOMINAL_LIGHT = 0.8


@dataclass(frozen=True)
class Item:
    """A task object at its nominal pose; ``colors`` restricts the variants it may take."""

    name: str
    type: str
    xy: tuple[float, float]
    yaw: float = 0.0
    colors: tuple[str, ...] | None = None
    jitter: bool = True  # False pins the pose (still scaled/coloured when randomised)


def _uniform(rng: np.random.Generator, r: Range) -> float:
    return float(rng.uniform(r.low, r.high)) if r.width > 0 else r.low


def randomize(items: Sequence[Item], rng: np.random.Generator, rand: Randomization) -> SceneSpec:
    """The scene for ``items``: nominal when ``rand.enabled`` is False, else randomised by ``rng``."""
    objects = []
    for item in items:
        otype = CATALOG.get(item.type)
        variants = item.colors or tuple(otype.colors)
        if not rand.enabled:
            objects.append(ObjectSpec(item.name, item.type, item.xy, item.yaw, 1.0, variants[0]))
            continue
        lo = max(otype.scale_range[0], rand.scale.low)
        hi = min(otype.scale_range[1], rand.scale.high)
        jitter = item.jitter
        xy = (item.xy[0] + (_uniform(rng, rand.object_xy) if jitter else 0.0),
              item.xy[1] + (_uniform(rng, rand.object_xy) if jitter else 0.0))
        objects.append(ObjectSpec(
            item.name, item.type, xy,
            yaw=item.yaw + (_uniform(rng, rand.object_yaw) if jitter else 0.0),
            scale=float(rng.uniform(lo, hi)) if hi > lo else 1.0,
            color=str(variants[rng.integers(len(variants))]) if rand.color else variants[0],
            friction=_uniform(rng, rand.friction),
        ))
    if not rand.enabled:
        return SceneSpec(objects=tuple(objects))
    table = TableSpec(
        height=NOMINAL_TABLE_HEIGHT + _uniform(rng, rand.table_height),
        rgba=TABLE_COLORS[rng.integers(len(TABLE_COLORS))] if rand.color else TABLE_COLORS[0],
        texture=TABLE_TEXTURES[rng.integers(len(TABLE_TEXTURES))] if rand.color else "plain",
    )
    cam = tuple(_uniform(rng, rand.camera_jitter) for _ in range(3))
    return SceneSpec(objects=tuple(objects), table=table, light=_uniform(rng, rand.light),
                     camera_offset=cam)  # type: ignore[arg-type]
