"""The figures of verification and evaluation: success rate, its Wilson interval, pass@k."""

from __future__ import annotations

import math
from collections.abc import Sequence

Z95 = 1.959963984540054  # two-sided 95 %
ACCEPT_ABOVE = 0.5  # a subtask is accepted iff its success rate is strictly greater than this


def wilson(successes: int, trials: int, z: float = Z95) -> tuple[float, float]:
    """The Wilson score interval of a success rate (95 % by default); (0, 1) for no trials."""
    if trials <= 0:
        return 0.0, 1.0
    p = successes / trials
    denom = 1 + z * z / trials
    centre = (p + z * z / (2 * trials)) / denom
    half = z * math.sqrt(p * (1 - p) / trials + z * z / (4 * trials * trials)) / denom
    lo = 0.0 if successes == 0 else max(0.0, centre - half)
    hi = 1.0 if successes == trials else min(1.0, centre + half)
    return lo, hi


def accepted(successes: int, trials: int) -> bool:
    """The paper's rule: accept iff SR > 0.5, a strict inequality (5 of 10 is rejected)."""
    return trials > 0 and successes / trials > ACCEPT_ABOVE


def pass_at_k(n: int, c: int, k: int) -> float:
    """The unbiased estimator of pass@k from ``n`` samples of which ``c`` are correct:
    ``1 - C(n - c, k) / C(n, k)`` (Chen et al., 2021)."""
    if not 0 <= c <= n or k < 1 or k > n:
        raise ValueError(f"pass@k needs 0 <= c <= n and 1 <= k <= n, got n={n}, c={c}, k={k}")
    if n - c < k:
        return 1.0
    return 1.0 - math.comb(n - c, k) / math.comb(n, k)


def top_k_mean(rates: Sequence[float], k: int = 3) -> float:
    """The mean of the ``k`` best success rates (Top-k SR); the mean of all when fewer."""
    best = sorted(rates, reverse=True)[:k]
    return sum(best) / len(best) if best else 0.0
