"""What a generation run does, as data: stored with the dataset and compared on append."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

from vcage.config import Randomization
from vcage.errors import ConfigError

MODES = ("vcage", "vanilla")


@dataclass(frozen=True)
class GenerateConfig:
    """``mode="vanilla"`` is the paper's baseline: naive placement, no scene check, no critic
    (an episode is accepted when no exception occurred); ``vcage`` uses ``placement`` and ``critic``."""

    mode: str = "vcage"
    planner: str = "offline"
    critic: str = "image"
    placement: str = "context"
    clutter: int = 4
    seed: int = 0
    max_attempts: int = 10  # scene re-samples per episode before the episode is given up
    cameras: tuple[str, ...] = ("front", "panda/wrist")  # recorded as videos
    size: tuple[int, int] = (128, 128)  # width, height of the videos
    critic_size: tuple[int, int] = (320, 240)  # width, height of the critic's views
    randomization: Randomization = field(default_factory=Randomization)

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise ConfigError(f"mode {self.mode!r}; valid: {', '.join(MODES)}")
        if self.clutter < 0 or self.max_attempts < 1:
            raise ConfigError("clutter must be >= 0 and max_attempts >= 1")
        if any(v <= 0 or v % 2 for v in self.size):
            raise ConfigError(f"video size {self.size} must be positive and even")
        if not self.cameras:
            raise ConfigError("record at least one camera")

    @property
    def placement_method(self) -> str:
        return "naive" if self.mode == "vanilla" else self.placement

    @property
    def check_scene(self) -> bool:
        return self.mode == "vcage"

    @property
    def critic_name(self) -> str | None:
        return None if self.mode == "vanilla" else self.critic

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        for key in ("cameras", "size", "critic_size"):
            d[key] = list(d[key])
        return d

    def episode_seed(self, episode: int, attempt: int) -> int:
        """The seed of an attempt: derived from the run seed, the episode and the attempt index."""
        import numpy as np

        return int(np.random.SeedSequence([self.seed, episode, attempt]).generate_state(1)[0])
