"""Instruction grounding: the ``Plan`` schema and the planners that produce it.

``make_planner(PlannerConfig("offline"))`` needs no network; ``PlannerConfig("llm", backend)``
talks to any OpenAI-compatible endpoint or Gemini (from the ``VCAGE_LLM_*`` environment variables
when the config names no backend).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from vcage.backends import BackendConfig, connect
from vcage.planning.config import PlannerConfig
from vcage.planning.llm import LLMPlanner
from vcage.planning.offline import OfflinePlanner
from vcage.planning.schema import GoalMatch, Plan
from vcage.registry import Registry

LLM_ENV_PREFIX = "VCAGE_LLM"  # where the endpoint is read from when the config names none


class Planner(Protocol):
    name: str

    def plan(self, instruction: str) -> Plan: ...


PlannerFactory = Callable[[PlannerConfig], Planner]
PLANNERS: Registry[PlannerFactory] = Registry("planner")
PLANNERS.add("offline", lambda cfg: OfflinePlanner(max_subtasks=cfg.max_subtasks))
PLANNERS.add("llm", lambda cfg: LLMPlanner(connect(cfg.backend or BackendConfig.from_env(LLM_ENV_PREFIX)),
                                           max_subtasks=cfg.max_subtasks))


def make_planner(config: PlannerConfig | str = "offline") -> Planner:
    """The planner ``config`` names (a bare name: its default config)."""
    cfg = PlannerConfig(config) if isinstance(config, str) else config
    return PLANNERS.get(cfg.name)(cfg)


__all__ = ["PLANNERS", "GoalMatch", "LLMPlanner", "OfflinePlanner", "Plan", "Planner", "PlannerConfig",
           "make_planner"]
