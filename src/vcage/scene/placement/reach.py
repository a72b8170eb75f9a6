"""Where the arm can reach with a top-down grasp, as data the placement map can use.

The Panda's first joint turns the whole arm about the base's vertical axis, so top-down
reachability depends only on the horizontal distance ``r`` from the base axis and the height
``z`` above the base. A :class:`ReachMap` stores, per height, the interval of ``r`` in which IK
found a top-down configuration. It is computed by :mod:`vcage.skills.reachability` (which owns IK) once
per robot and cached on disk; this module only reads it.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from shapely.geometry.base import BaseGeometry

from vcage.errors import SceneError
from vcage.scene.placement.geometry import annulus

# Heights above the table the gripper must reach over a placed object's origin: from a low grasp
# up to the lift height the skills use.
GRASP_BAND = (0.03, 0.25)


@dataclass(frozen=True)
class ReachMap:
    heights: tuple[float, ...]  # z above the robot base, ascending
    r_min: tuple[float, ...]  # per height; r_min > r_max where nothing is reachable
    r_max: tuple[float, ...]
    mount: tuple[float, float, float]

    def interval(self, table_top: float, band: tuple[float, float] = GRASP_BAND) -> tuple[float, float]:
        """The radii from the base axis at which every height of ``band`` above ``table_top`` is
        reachable top-down (an empty interval if there are none)."""
        z = np.asarray(self.heights)
        lo_z, hi_z = table_top - self.mount[2] + band[0], table_top - self.mount[2] + band[1]
        if lo_z < z[0] or hi_z > z[-1]:
            raise SceneError(f"table top {table_top:.3f} m is outside the heights the reach map "
                             f"covers ({z[0] + self.mount[2]:.2f} to {z[-1] + self.mount[2]:.2f} m)")
        probe = np.linspace(lo_z, hi_z, 12)
        r_in = float(np.max(np.interp(probe, z, self.r_min)))
        r_out = float(np.min(np.interp(probe, z, self.r_max)))
        return r_in, r_out

    def region(self, table_top: float, band: tuple[float, float] = GRASP_BAND) -> BaseGeometry:
        """The table positions (x, y) reachable top-down at every height of ``band``."""
        r_in, r_out = self.interval(table_top, band)
        return annulus(self.mount[:2], r_in, max(r_out, r_in))

    def to_json(self) -> str:
        return json.dumps({"heights": self.heights, "r_min": self.r_min, "r_max": self.r_max,
                           "mount": self.mount})

    @classmethod
    def from_json(cls, text: str) -> ReachMap:
        d = json.loads(text)
        return cls(tuple(d["heights"]), tuple(d["r_min"]), tuple(d["r_max"]), tuple(d["mount"]))

    def save(self, path: Path) -> None:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(self.to_json())
        tmp.replace(path)  # atomic: concurrent workers never read half a file
