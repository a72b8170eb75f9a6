"""Instruction grounding: the ``Plan`` schema and the planners that produce it.

``make_planner("offline")`` needs no network; ``make_planner("llm", backend_config)`` talks to any
OpenAI-compatible endpoint (configured from ``VCAGE_LLM_*`` environment variables when no config
is given).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from vcage.backends import BackendConfig, connect
from vcage.planning.llm import LLMPlanner
from vcage.planning.offline import OfflinePlanner
from vcage.planning.schema import Plan
from vcage.registry import Registry


class Planner(Protocol):
    name: str

    def plan(self, instruction: str) -> Plan: ...


PlannerFactory = Callable[[BackendConfig | None], Planner]
PLANNERS: Registry[PlannerFactory] = Registry("planner")
PLANNERS.add("offline", lambda cfg: OfflinePlanner())
PLANNERS.add("llm", lambda cfg: LLMPlanner(connect(cfg or BackendConfig.from_env())))


def make_planner(name: str = "offline", backend: BackendConfig | None = None) -> Planner:
    return PLANNERS.get(name)(backend)


__all__ = ["PLANNERS", "LLMPlanner", "OfflinePlanner", "Plan", "Planner", "make_planner"]
