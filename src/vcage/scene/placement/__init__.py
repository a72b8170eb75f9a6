"""Scene instantiation: turn a :class:`~vcage.scene.layout.LayoutSpec` into posed objects.

Methods (registered in :data:`PLACERS`): ``context`` (the prohibited-region map, the default),
``naive`` (uniform, unchecked: the paper's Vanilla) and ``rejection`` (robosuite-style bounding
cylinders with a fixed number of tries).
"""

from __future__ import annotations

import numpy as np

from vcage.scene.layout import LayoutSpec
from vcage.scene.placement import baselines, context  # noqa: F401  (register the methods)
from vcage.scene.placement.base import PLACERS, PlacementConfig, PlacementResult, PlacementStats, Placer
from vcage.scene.placement.reach import ReachMap

DEFAULT_METHOD = "context"


def make_placer(method: str = DEFAULT_METHOD, config: PlacementConfig | None = None,
                reach: ReachMap | None = None) -> Placer:
    return PLACERS.get(method)(config, reach)


def place(layout: LayoutSpec, rng: np.random.Generator, method: str = DEFAULT_METHOD,
          config: PlacementConfig | None = None, reach: ReachMap | None = None) -> PlacementResult:
    """Place ``layout``'s objects with ``method``; raises :class:`PlacementError` if impossible."""
    return make_placer(method, config, reach).place(layout, rng)


__all__ = ["DEFAULT_METHOD", "PLACERS", "PlacementConfig", "PlacementResult", "PlacementStats",
           "Placer", "ReachMap", "make_placer", "place"]
