"""One small real dataset for the report's tests, made once with ``vcage generate``.

A scripted critic that looks at the rendered views (so the pipeline keeps what it saw) accepts
the 1st, 4th, 7th ... subtask it judges and rejects the others. With one subtask per episode
("press the bell", which the oracle says succeeds) and two attempts per episode, the run accepts
sample 0, gives up sample 1 after two rejections, and accepts sample 2: three episodes asked for,
two accepted, two rejected attempts, both disagreements with the oracle (false rejects).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from vcage.cli import app
from vcage.cli.errors import EXIT_PARTIAL
from vcage.critics import CRITICS, Critic, Observation, Verdict

CRITIC = "report_every_third"
GENERATE = ["generate", "press the bell", "--episodes", "3", "--critic", CRITIC, "--max-attempts", "2",
            "--clutter", "0", "--size", "64", "--seed", "5"]


class EveryThirdAccepts(Critic):
    """Accepts calls 1, 4, 7, ...; judges nothing, but asks for views like an image critic."""

    needs_views = True

    def __init__(self) -> None:
        self.calls = 0

    def judge(self, obs: Observation) -> Verdict:
        self.calls += 1
        assert obs.after, "the pipeline rendered the views this critic asks for"
        accept = self.calls % 3 == 1
        return Verdict(accept, f"scripted {'accept' if accept else 'reject'} (call {self.calls})")


if CRITIC not in CRITICS:
    CRITICS.add(CRITIC, lambda config: EveryThirdAccepts())


@pytest.fixture(scope="session")
def dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("report") / "ds"
    made = CliRunner().invoke(app, [*GENERATE, "--out", str(out)])
    assert made.exit_code == EXIT_PARTIAL, made.output  # one of the three episodes was given up
    return out
