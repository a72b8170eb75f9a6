"""The oracle as a critic: accepts exactly when the subtask's ground-truth predicates hold.

Useful as an upper bound and for debugging; the default critics judge from images only.
"""

from __future__ import annotations

from vcage.critics.base import CRITICS, Critic, CriticConfig, Observation, Verdict


class OracleCritic(Critic):
    name = "oracle"
    needs_views = False

    def judge(self, obs: Observation) -> Verdict:
        """A rejection's ``codes`` name each predicate that does not hold, by its name (``pressed.false``
        for ``pressed(bell)``), in the oracle's order."""
        failed = [k for k, v in obs.oracle.items() if not v]
        if failed:
            codes = tuple(f"{k.split('(')[0].strip()}.false" for k in failed)
            return Verdict(False, "predicates do not hold: " + ", ".join(failed), codes=codes)
        return Verdict(True, "all predicates hold: " + ", ".join(obs.oracle))


@CRITICS.register("oracle")
def _oracle(config: CriticConfig) -> Critic:
    return OracleCritic()
