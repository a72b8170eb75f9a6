"""Register every atomic task as a Gymnasium environment ``vcage/<task name>-v0``.

    from vcage.tasks.gym_registration import env_id, register_envs
    import gymnasium as gym

    register_envs()
    env = gym.make(env_id("stack_blocks_two"), cameras=("front",))

Keyword arguments of ``gym.make`` go to :class:`vcage.tasks.env.TaskEnv`. Registration is explicit
(nothing is registered on import) and idempotent; call it again after more tasks are registered to
add theirs.
"""

from __future__ import annotations

import gymnasium as gym

from vcage.tasks.base import TASKS

__all__ = ["ENTRY_POINT", "NAMESPACE", "env_id", "register_envs"]

NAMESPACE = "vcage"
ENTRY_POINT = "vcage.tasks.env:TaskEnv"


def env_id(task_name: str) -> str:
    """The Gymnasium id of task ``task_name``: ``"vcage/<task_name>-v0"``."""
    return f"{NAMESPACE}/{task_name}-v0"


def register_envs() -> list[str]:
    """Register every task in ``TASKS`` (built-ins included) not registered yet; return all ids."""
    import vcage.tasks.library  # noqa: F401  (registers the built-in tasks)

    ids = []
    for name in TASKS.names():
        eid = env_id(name)
        if eid not in gym.registry:
            gym.register(id=eid, entry_point=ENTRY_POINT, kwargs={"task": name})
        ids.append(eid)
    return ids
