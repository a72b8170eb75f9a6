"""Critics with scripted verdicts, registered once for the tests that need a given-up episode.

They implement the real ``Critic`` interface (the pipeline's extension point), so the rejection
paths run through the real sampling loop, writer and command line.
"""

from __future__ import annotations

from vcage.critics import CRITICS, Critic, Observation, Verdict


class RejectAll(Critic):
    """Rejects every subtask: every episode is given up."""

    needs_views = False

    def judge(self, obs: Observation) -> Verdict:
        return Verdict(False, "rejects everything")


class AcceptAll(Critic):
    """Accepts every subtask: what the oracle says failed goes into the dataset (label noise)."""

    needs_views = False

    def judge(self, obs: Observation) -> Verdict:
        return Verdict(True, "accepts everything")


class Alternating(Critic):
    """Accepts, rejects, accepts, ... in call order: with one subtask and one attempt per episode,
    every second episode is given up."""

    needs_views = False

    def __init__(self) -> None:
        self.calls = 0

    def judge(self, obs: Observation) -> Verdict:
        self.calls += 1
        return Verdict(self.calls % 2 == 1, f"call {self.calls}")


for _name, _cls in (("reject_all", RejectAll), ("alternating", Alternating), ("accept_all", AcceptAll)):
    if _name not in CRITICS:  # several test modules import this one
        CRITICS.add(_name, lambda config, cls=_cls: cls())
