"""Which planner grounds instructions, and the model endpoint of an LLM planner."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from vcage.backends import BackendConfig
from vcage.config import from_fields


@dataclass(frozen=True)
class PlannerConfig:
    """``backend`` is the LLM planner's endpoint; when None the ``VCAGE_LLM_*`` environment
    variables are read once, when the run's configuration is resolved, and stored with the data."""

    name: str = "offline"
    backend: BackendConfig | None = None

    def __post_init__(self) -> None:
        from vcage.planning import PLANNERS  # the package registers them on import

        PLANNERS.get(self.name)  # an unknown name lists the valid ones

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "backend": self.backend.to_dict() if self.backend else None}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> PlannerConfig:
        return from_fields(cls, data, backend=BackendConfig)
