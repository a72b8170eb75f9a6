"""Gymnasium registration of every atomic task as ``vcage/<task name>-v0``.

``import vcage`` registers the built-in tasks (their ids only: no task, simulator or renderer is
imported until ``gym.make``), so in a fresh interpreter::

    import gymnasium as gym
    import vcage  # noqa: F401

    env = gym.make("vcage/stack_blocks_two-v0", cameras=("front",))

or, without importing vcage yourself, ``gym.make("vcage:vcage/stack_blocks_two-v0")``.
Keyword arguments of ``gym.make`` go to :class:`vcage.tasks.env.TaskEnv`. Tasks registered later
(your own, in ``TASKS``) are added by :func:`register_envs`.
"""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym

__all__ = ["ENTRY_POINT", "NAMESPACE", "builtin_task_names", "env_id", "register_envs"]

NAMESPACE = "vcage"
ENTRY_POINT = "vcage.tasks.env:TaskEnv"
LIBRARY = Path(__file__).parent / "tasks" / "library"  # one module per built-in task, named after it


def env_id(task_name: str) -> str:
    """The Gymnasium id of task ``task_name``: ``"vcage/<task_name>-v0"``."""
    return f"{NAMESPACE}/{task_name}-v0"


def builtin_task_names() -> list[str]:
    """The built-in tasks, from the library's module names (without importing them)."""
    return sorted(p.stem for p in LIBRARY.glob("*.py") if not p.stem.startswith("_"))


def _register(names: list[str]) -> list[str]:
    ids = []
    for name in names:
        eid = env_id(name)
        if eid not in gym.registry:
            gym.register(id=eid, entry_point=ENTRY_POINT, kwargs={"task": name})
        ids.append(eid)
    return ids


def register_builtin_envs() -> list[str]:
    """Register the built-in tasks' environments; idempotent. Called by ``import vcage``."""
    return _register(builtin_task_names())


def register_envs() -> list[str]:
    """Register every task in ``TASKS`` (built-ins and your own) not registered yet; return all ids."""
    from vcage.tasks import TASKS

    return _register(TASKS.names())
