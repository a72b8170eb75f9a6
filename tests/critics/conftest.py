"""The critic's tests judge stored observations (``recipes.py``, ``observations/``) and scenes at rest,
never a rollout made again: a new release of the simulator moves chaotic rollouts, and then these
tests would test the physics rather than the critic. A test here that moves the robot fails."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from vcage.skills.base import Skills


@pytest.fixture(autouse=True)
def _no_rollouts(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    def refuse(*_: Any, **__: Any) -> None:
        raise AssertionError("a critic test rolls a subtask out: store the observation it needs with "
                             "tests/critics/recipes.py and read it with recipes.observed")

    monkeypatch.setattr(Skills, "__init__", refuse)
    yield
