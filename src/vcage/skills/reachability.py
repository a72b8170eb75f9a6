"""Compute the top-down :class:`ReachMap` of the Panda with IK, once, and cache it on disk.

For each height above the base, IK solves for the gripper pointing down at radii along the
base's x axis, each from the home configuration; the longest run of solved radii is the
interval. About 700 solves take a few seconds; the result is cached under
``$XDG_CACHE_HOME/vcage`` (or ``~/.cache/vcage``) keyed by the mount and the grid.
"""

from __future__ import annotations

import contextlib
import hashlib
from functools import cache

import numpy as np

from vcage.config import cache_dir
from vcage.errors import SkillError
from vcage.scene.placement.reach import ReachMap
from vcage.scene.spec import ROBOT_MOUNT
from vcage.sim.robot import HOME_QPOS
from vcage.skills.ik import IKSolver, down_rotation

HEIGHTS = tuple(round(-0.15 + 0.05 * i, 3) for i in range(12))  # -0.15 .. 0.40 m above the base
RADII = tuple(round(0.10 + 0.01 * i, 3) for i in range(81))  # 0.10 .. 0.90 m from the base axis
VERSION = 1  # bump when the IK model or the criterion changes



def compute_reach_map(mount: tuple[float, float, float] = ROBOT_MOUNT) -> ReachMap:
    solver = IKSolver(mount)
    home = np.asarray(HOME_QPOS, dtype=float)
    r_min, r_max = [], []
    for dz in HEIGHTS:
        ok = []
        for r in RADII:
            try:  # seeded from home, as the skills start from near it
                solver.solve(np.asarray(mount) + [r, 0.0, dz], down_rotation(0.0), home)
            except SkillError:
                ok.append(False)
                continue
            ok.append(True)
        lo, hi = _longest_run(ok)
        r_min.append(RADII[lo] if hi >= lo else 1.0)
        r_max.append(RADII[hi] if hi >= lo else 0.0)
    return ReachMap(HEIGHTS, tuple(r_min), tuple(r_max), tuple(mount))  # type: ignore[arg-type]


def _longest_run(flags: list[bool]) -> tuple[int, int]:
    """First and last index of the longest run of True (``(0, -1)`` if there is none)."""
    best, start = (0, -1), None
    for i, flag in enumerate([*flags, False]):
        if flag and start is None:
            start = i
        elif not flag and start is not None:
            if i - 1 - start > best[1] - best[0]:
                best = (start, i - 1)
            start = None
    return best


@cache
def reach_map(mount: tuple[float, float, float] = ROBOT_MOUNT) -> ReachMap:
    """The reach map for a robot at ``mount``, from the disk cache or computed and stored."""
    key = hashlib.sha1(repr((VERSION, mount, HEIGHTS, RADII)).encode()).hexdigest()[:12]
    path = cache_dir() / f"reach-{key}.json"
    if path.exists():
        try:
            return ReachMap.from_json(path.read_text())
        except (ValueError, KeyError):
            pass  # a corrupt cache file is recomputed and overwritten
    result = compute_reach_map(mount)
    with contextlib.suppress(OSError):  # a read-only home still gets the map, just not cached
        result.save(path)
    return result
