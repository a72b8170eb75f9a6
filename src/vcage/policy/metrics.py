"""Success statistics of evaluation episodes (no torch)."""

from __future__ import annotations

import math
from collections.abc import Sequence

Z95 = 1.959963984540054  # two-sided 95% normal quantile


def wilson_interval(successes: int, n: int, z: float = Z95) -> tuple[float, float]:
    """The Wilson score interval of a success rate (95% by default); (0, 1) when ``n`` is 0."""
    if n <= 0:
        return 0.0, 1.0
    if not 0 <= successes <= n:
        raise ValueError(f"successes must be in [0, {n}], got {successes}")
    p = successes / n
    denom = 1 + z * z / n
    center = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    return max(0.0, center - half), min(1.0, center + half)


def subtask_reached(done: Sequence[int], subtasks: int) -> list[float]:
    """For each subtask, the share of episodes that completed it (episodes completed ``done[k]``
    subtasks each, in order)."""
    if not done:
        return [0.0] * subtasks
    return [sum(d > i for d in done) / len(done) for i in range(subtasks)]
