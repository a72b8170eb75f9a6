"""Executors: results in episode order with a bounded window; early stops cancel what has not run."""

from __future__ import annotations

import pytest

from vcage.errors import ConfigError, RegistryError
from vcage.pipeline.config import ExecutorConfig
from vcage.pipeline.executors import AHEAD, EXECUTORS, LocalExecutor, _in_order, make_executor
from vcage.pipeline.sampling import EpisodeRun


class Log:
    def __init__(self) -> None:
        self.submitted: list[int] = []
        self.cancelled: list[int] = []

    def submit(self, k: int) -> int:
        self.submitted.append(k)
        return k

    def result(self, k: int) -> EpisodeRun:
        return EpisodeRun(k)

    def cancel(self, k: int) -> None:
        self.cancelled.append(k)


def test_results_in_order_with_a_bounded_window() -> None:
    log = Log()
    runs = _in_order(log.submit, log.result, log.cancel, range(3, 10), workers=2)
    first = next(runs)
    assert first.index == 3 and log.submitted == [3, 4, 5, 6, 7]  # AHEAD * workers, then one more
    assert [r.index for r in runs] == list(range(4, 10)) and log.cancelled == []
    assert AHEAD == 2


def test_stopping_early_cancels_the_pending_episodes() -> None:
    log = Log()
    runs = _in_order(log.submit, log.result, log.cancel, range(10), workers=1)
    assert next(runs).index == 0
    runs.close()  # e.g. the writer raised
    assert log.cancelled == [1, 2]


def test_executor_arguments_are_checked_when_built() -> None:
    assert EXECUTORS.names() == ["local", "ray"]
    with pytest.raises(ConfigError, match="workers"):
        ExecutorConfig(workers=0)
    with pytest.raises(ConfigError, match="--executor ray"):
        LocalExecutor(ExecutorConfig(workers=2, address="auto"))
    with pytest.raises(RegistryError, match="valid names: local, ray"):
        make_executor(ExecutorConfig("slurm"))
