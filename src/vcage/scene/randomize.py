"""Seeded domain randomisation of a layout: each object's look, and the table, light and cameras.

Task layouts and plan layouts both draw through these two functions, in the same order (each
object's look in layout order, then the environment), so a seed means the same draws everywhere.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from vcage.assets.catalog import CATALOG
from vcage.config import Randomization, Range
from vcage.scene.spec import TableSpec

TABLE_COLORS = ((0.62, 0.47, 0.33, 1.0), (0.75, 0.75, 0.72, 1.0), (0.35, 0.28, 0.22, 1.0),
                (0.55, 0.6, 0.65, 1.0))
TABLE_TEXTURES = ("plain", "checker", "grid")
NOMINAL_TABLE_HEIGHT = 0.75
NOMINAL_LIGHT = 0.8


def uniform(rng: np.random.Generator, r: Range) -> float:
    """A draw from ``r``; a zero-width range is its value and draws nothing."""
    return float(rng.uniform(r.low, r.high)) if r.width > 0 else r.low


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
    return scale, color, uniform(rng, rand.friction)


def environment(rng: np.random.Generator, rand: Randomization) -> dict[str, Any]:
    """Table, light and camera jitter of a layout (``LayoutSpec`` fields): nominal, or drawn."""
    if not rand.enabled:
        return {}
    table = TableSpec(
        height=NOMINAL_TABLE_HEIGHT + uniform(rng, rand.table_height),
        rgba=TABLE_COLORS[rng.integers(len(TABLE_COLORS))] if rand.color else TABLE_COLORS[0],
        texture=TABLE_TEXTURES[rng.integers(len(TABLE_TEXTURES))] if rand.color else "plain",
    )
    cam = (uniform(rng, rand.camera_jitter), uniform(rng, rand.camera_jitter),
           uniform(rng, rand.camera_jitter))
    return {"table": table, "light": uniform(rng, rand.light), "camera_offset": cam}
