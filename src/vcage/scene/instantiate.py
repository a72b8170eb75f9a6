"""Scene instantiation, the one path from a layout to a world ready for the robot.

layout → place (context-aware by default) → compose → settle, checking physical validity while it
settles. Atomic tasks and long-horizon plans both instantiate their scenes here, so a scene is
valid by the same rules whatever asked for it.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from vcage.config import SimConfig, from_fields
from vcage.errors import ConfigError, UnstableSceneError
from vcage.scene.compose import compose
from vcage.scene.layout import LayoutSpec
from vcage.scene.placement import DEFAULT_METHOD, PLACERS, PlacementConfig, PlacementStats, ReachMap, place
from vcage.scene.spec import SceneSpec
from vcage.scene.stability import StabilityConfig, StabilityReport, check_stability
from vcage.sim.world import World


@dataclass(frozen=True)
class SceneConfig:
    """How scenes are instantiated: placement method, clutter, and the physics check.

    ``check=False`` (the Vanilla baseline) settles the scene without checking it.
    """

    placement: str = DEFAULT_METHOD  # "context" | "naive" | "rejection"
    clutter: int = 0  # distractors added around the task's objects
    check: bool = True  # verify the scene in physics before the robot acts
    settle_seconds: float = 0.3  # physics time the scene settles (and is checked) before acting
    placement_config: PlacementConfig = field(default_factory=PlacementConfig)

    def __post_init__(self) -> None:
        PLACERS.get(self.placement)  # unknown methods list the valid ones
        if isinstance(self.clutter, bool) or not isinstance(self.clutter, int) or self.clutter < 0:
            raise ConfigError(f"clutter {self.clutter!r} must be an integer >= 0")
        if not 0 < self.settle_seconds <= 10:
            raise ConfigError(f"settle_seconds {self.settle_seconds} must lie in (0, 10]")

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> SceneConfig:
        return from_fields(cls, data, placement_config=PlacementConfig)


@dataclass
class SceneInstance:
    """A placed, composed and settled scene; ``stability`` is None when it was not checked."""

    spec: SceneSpec
    world: World
    placement: PlacementStats
    stability: StabilityReport | None

    @property
    def valid(self) -> bool:
        return self.stability is None or self.stability.ok

    def require_valid(self, what: str) -> None:
        """Raise :class:`UnstableSceneError` naming ``what`` and the reason if the check failed."""
        if not self.valid:
            assert self.stability is not None
            raise UnstableSceneError(f"the scene of {what} is not physically valid: "
                                     f"{self.stability.reason()}")


@dataclass(frozen=True)
class Instantiator:
    """Instantiates layouts with one scene config, physics config and reach map."""

    scene: SceneConfig = field(default_factory=SceneConfig)
    sim: SimConfig = field(default_factory=SimConfig)
    reach: ReachMap | None = None  # the arm's reach; None places without it

    def place(self, layout: LayoutSpec, rng: np.random.Generator) -> tuple[SceneSpec, PlacementStats]:
        """Place ``layout``'s objects; raises :class:`PlacementError` when they do not fit."""
        result = place(layout, rng, self.scene.placement, self.scene.placement_config, self.reach)
        return result.scene, result.stats

    def realize(self, spec: SceneSpec, stats: PlacementStats) -> SceneInstance:
        """Compose ``spec`` and let it settle, checking it unless the config says not to.

        Raises :class:`SimulationError` if the physics blows up while the world is built.
        """
        world = compose(spec, self.sim).make_world(self.sim)
        report = None
        if self.scene.check:  # settles the world as it checks it
            report = check_stability(world, StabilityConfig(settle_seconds=self.scene.settle_seconds))
        else:
            world.settle(self.scene.settle_seconds)
        return SceneInstance(spec, world, stats, report)

    def instantiate(self, layout: LayoutSpec, rng: np.random.Generator) -> SceneInstance:
        return self.realize(*self.place(layout, rng))
