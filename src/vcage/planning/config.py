"""Which planner grounds instructions, the model endpoint of an LLM planner, and the plan-length cap."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from vcage.backends import BackendConfig
from vcage.config import from_fields
from vcage.errors import ConfigError

MAX_SUBTASKS = 8  # default cap on a plan's subtasks (the goal library's goals have 3 to 6)


@dataclass(frozen=True)
class PlannerConfig:
    """``backend`` is the LLM planner's endpoint; when None the ``VCAGE_LLM_*`` environment
    variables are read once, when the run's configuration is resolved, and stored with the data.
    ``max_subtasks`` caps every plan, from any planner: a longer one is refused, never shortened."""

    name: str = "offline"
    backend: BackendConfig | None = None
    max_subtasks: int = MAX_SUBTASKS

    def __post_init__(self) -> None:
        from vcage.planning import PLANNERS  # the package registers them on import

        PLANNERS.get(self.name)  # an unknown name lists the valid ones
        cap = self.max_subtasks
        if isinstance(cap, bool) or not isinstance(cap, int) or cap < 1:
            raise ConfigError(f"PlannerConfig.max_subtasks must be an integer >= 1 (the most subtasks a plan "
                              f"may have; default {MAX_SUBTASKS}), got {self.max_subtasks!r}")

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "backend": self.backend.to_dict() if self.backend else None,
                "max_subtasks": self.max_subtasks}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> PlannerConfig:
        return from_fields(cls, data, backend=BackendConfig)
