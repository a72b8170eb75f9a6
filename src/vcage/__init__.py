"""vcage: verified long-horizon robot manipulation datasets in simulation.

The public API, imported on first use (``import vcage`` itself loads no simulator)::

    import vcage
    funnel = vcage.generate("get ready for work", 5, "out/ds", vcage.GenerateConfig())
    ep = vcage.DatasetReader("out/ds").episode(0)

``import vcage`` also registers every built-in atomic task as a Gymnasium environment
(``gym.make("vcage/stack_blocks_two-v0")``, see :mod:`vcage.envs`).
"""

from __future__ import annotations

import importlib
from typing import Any

from vcage.numerics import pin

NUMERICS = pin()  # before anything loads NumPy: the same BLAS kernels on every x86-64 machine

from vcage.sim.gl import choose_gl_backend  # noqa: E402

# MUJOCO_GL must be set before mujoco is first imported; every vcage module imports this package
# first, so choosing the backend here covers them all.
choose_gl_backend()

from vcage.envs import register_builtin_envs  # noqa: E402

register_builtin_envs()

# moves when the episodes a seed gives would differ (0.2.0: installed from requirements/lock.txt)
__version__ = "0.2.0"

# public name -> module that defines it
_API = {
    "generate": "vcage.pipeline.generate",
    "GenerateConfig": "vcage.pipeline.config",
    "DatasetReader": "vcage.data",
    "DatasetWriter": "vcage.data",
    "make_planner": "vcage.planning",
    "Plan": "vcage.planning",
    "run_episode": "vcage.tasks",
    "TASKS": "vcage.tasks",
    "Randomization": "vcage.config",
    "SimConfig": "vcage.config",
    "VcageError": "vcage.errors",
    "audit": "vcage.pipeline.audit",
}
__all__ = sorted(_API)


def __getattr__(name: str) -> Any:
    if name in _API:
        return getattr(importlib.import_module(_API[name]), name)
    raise AttributeError(f"module 'vcage' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*globals(), *_API])
