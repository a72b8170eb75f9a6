"""A task's nominal items, seeded domain randomisation, and the :class:`LayoutSpec` they make.

The layout goes through a placement method (context-aware by default), so randomised poses never
interpenetrate and clutter can be added around the task's objects.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from vcage.assets.catalog import CATALOG
from vcage.config import Randomization, Range
from vcage.errors import ConfigError
from vcage.scene.layout import Distractors, LayoutObject, LayoutSpec, Region, Relation, ReservedZone
from vcage.scene.placement import DEFAULT_METHOD, PLACERS, PlacementConfig
from vcage.scene.spec import TableSpec

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


@dataclass(frozen=True)
class SceneConfig:
    """How a task's scene is instantiated: placement method, clutter, and placement settings."""

    placement: str = DEFAULT_METHOD  # "context" | "naive" | "rejection"
    clutter: int = 0  # distractors added around the task's objects
    check: bool = True  # verify the scene in physics before the expert runs (off for Vanilla)
    config: PlacementConfig = field(default_factory=PlacementConfig)

    def __post_init__(self) -> None:
        PLACERS.get(self.placement)  # unknown methods list the valid ones
        if self.clutter < 0:
            raise ConfigError(f"clutter {self.clutter} must be >= 0")

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def _uniform(rng: np.random.Generator, r: Range) -> float:
    return float(rng.uniform(r.low, r.high)) if r.width > 0 else r.low


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


def environment(rng: np.random.Generator, rand: Randomization) -> dict[str, Any]:
    """Table, light and camera jitter of a layout: nominal, or drawn from ``rng``."""
    if not rand.enabled:
        return {}
    table = TableSpec(
        height=NOMINAL_TABLE_HEIGHT + _uniform(rng, rand.table_height),
        rgba=TABLE_COLORS[rng.integers(len(TABLE_COLORS))] if rand.color else TABLE_COLORS[0],
        texture=TABLE_TEXTURES[rng.integers(len(TABLE_TEXTURES))] if rand.color else "plain",
    )
    cam = (_uniform(rng, rand.camera_jitter), _uniform(rng, rand.camera_jitter),
           _uniform(rng, rand.camera_jitter))
    return {"table": table, "light": _uniform(rng, rand.light), "camera_offset": cam}


def object_look(otype_name: str, rng: np.random.Generator, rand: Randomization,
                colors: tuple[str, ...] | None = None) -> tuple[float, str, float]:
    """Scale, colour and friction of one object: nominal, or drawn from ``rng``."""
    otype = CATALOG.get(otype_name)
    variants = colors or tuple(otype.colors)
    if not rand.enabled:
        return 1.0, variants[0], 1.0
    lo_s = max(otype.scale_range[0], rand.scale.low)
    hi_s = min(otype.scale_range[1], rand.scale.high)
    scale = float(rng.uniform(lo_s, hi_s)) if hi_s > lo_s else 1.0
    color = str(variants[rng.integers(len(variants))]) if rand.color else variants[0]
    return scale, color, _uniform(rng, rand.friction)
