"""The software an episode depends on, by version: stored with what vcage makes.

The same seed gives the same episode only under the same versions of the simulator and the solvers
around it (MuJoCo's contacts, mink's and daqp's inverse kinematics, NumPy's random streams): the
rollouts of one commit were seen to differ between two machines that resolved the dependencies
at different times. Versions are read from the installed distributions' metadata, so nothing here
imports the simulator.
"""

from __future__ import annotations

import platform
from importlib.metadata import PackageNotFoundError, version

# the distributions whose versions decide what an episode holds
DISTRIBUTIONS = ("vcage", "mujoco", "mink", "daqp", "numpy", "scipy", "shapely", "trimesh",
                 "fast-simplification", "av")


def software() -> dict[str, str]:
    """``{distribution: version}`` for :data:`DISTRIBUTIONS` and Python ("absent" where one is not
    installed)."""
    out = {"python": platform.python_version()}
    for name in DISTRIBUTIONS:
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = "absent"
    return out
