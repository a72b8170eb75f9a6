"""Every phrasing a library goal lists grounds to that goal, word for word, with the offline planner.

("shut down for the night" once failed: its content words reduce to "off", which another goal's
phrasing, "show off the fruit", also holds, and the rival check called it ambiguous.)"""

from __future__ import annotations

import pytest

from vcage.planning import make_planner
from vcage.planning.config import PlannerConfig
from vcage.planning.goals import GOALS

PLANNER = make_planner(PlannerConfig())


@pytest.mark.parametrize("goal, phrasing", [(g.name, p) for g in GOALS for p in g.phrasings])
def test_a_goals_own_phrasing_grounds_to_it(goal: str, phrasing: str) -> None:
    assert PLANNER.plan(phrasing).goal == goal
