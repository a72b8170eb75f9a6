"""Where episodes run: in this process, in worker processes, or on a Ray cluster.

An executor is built with how many episodes may run at once (and, for Ray, where), checking those
before the run writes anything; :meth:`EpisodeExecutor.runs` then yields :class:`EpisodeRun`
results in episode order. Each episode's attempts depend only on its seeds, so every executor
produces the same dataset; they differ in how many episodes run at once. Register new ones in
``EXECUTORS``.
"""

from __future__ import annotations

import itertools
import multiprocessing
import os
from abc import ABC, abstractmethod
from collections import deque
from collections.abc import Callable, Iterator
from concurrent.futures import Future, ProcessPoolExecutor
from typing import Any, TypeVar

from vcage.critics import Critic
from vcage.errors import ConfigError
from vcage.lifetime import die_with_parent
from vcage.pipeline.config import ExecutorConfig, GenerateConfig
from vcage.pipeline.sampling import EpisodeRun, build_critic, sample_episode
from vcage.planning.schema import Plan
from vcage.registry import Registry

AHEAD = 2  # episodes submitted per worker before the first result is consumed
H = TypeVar("H")  # an executor's handle on a submitted episode


class EpisodeExecutor(ABC):
    """Runs episodes, at most ``config.workers`` at once."""

    def __init__(self, config: ExecutorConfig) -> None:
        self.config = config
        self.workers, self.address = config.workers, config.address

    @abstractmethod
    def runs(self, plan: Plan, cfg: GenerateConfig, indices: range,
             critic: Critic | None) -> Iterator[EpisodeRun]:
        """The episodes ``indices`` of ``plan``, in index order.

        ``critic`` judges episodes run in this process; worker processes build their own from
        ``cfg`` (a critic may hold connections that do not cross processes).
        """


EXECUTORS: Registry[type[EpisodeExecutor]] = Registry("executor")


def make_executor(config: ExecutorConfig) -> EpisodeExecutor:
    """The executor ``config`` names; checks its settings before any work."""
    return EXECUTORS.get(config.name)(config)


@EXECUTORS.register("local")
class LocalExecutor(EpisodeExecutor):
    """One worker: episodes in this process; more: that many worker processes on this machine."""

    def __init__(self, config: ExecutorConfig) -> None:
        super().__init__(config)
        if config.address is not None:
            raise ConfigError("the local executor runs on this machine; an address needs --executor ray")

    def runs(self, plan: Plan, cfg: GenerateConfig, indices: range,
             critic: Critic | None) -> Iterator[EpisodeRun]:
        if self.workers == 1:
            for k in indices:
                yield sample_episode(plan, k, cfg, critic)
            return
        context = multiprocessing.get_context("spawn")  # fresh processes: no GL context is forked
        with ProcessPoolExecutor(self.workers, mp_context=context, initializer=die_with_parent,
                                 initargs=(os.getpid(),)) as pool:
            yield from _in_order(lambda k: pool.submit(_episode, plan, cfg, k), Future.result,
                                 Future.cancel, indices, self.workers)


@EXECUTORS.register("ray")
class RayExecutor(EpisodeExecutor):
    """Episodes as Ray tasks (one CPU each), at most ``workers`` at a time.

    ``address`` is a running cluster's (``auto``, or ``ray://host:10001``); without one, a Ray
    instance already started in this process is used, or a local one is started for the run.
    Ray must be installed (``pip install 'vcage[ray]'``).
    """

    def __init__(self, config: ExecutorConfig) -> None:
        super().__init__(config)
        try:
            import ray
        except ImportError as exc:
            raise ConfigError("the ray executor needs Ray: pip install 'vcage[ray]'") from exc
        self.ray = ray

    def runs(self, plan: Plan, cfg: GenerateConfig, indices: range,
             critic: Critic | None) -> Iterator[EpisodeRun]:
        ray = self.ray
        started = not ray.is_initialized()
        if started:
            ray.init(address=self.address, include_dashboard=False, log_to_driver=False,
                     runtime_env={"env_vars": {"LP_NUM_THREADS": "1"}})
        try:
            task = ray.remote(num_cpus=1)(_episode)
            plan_ref, cfg_ref = ray.put(plan), ray.put(cfg)

            def submit(k: int) -> Any:  # a Ray object reference
                return task.remote(plan_ref, cfg_ref, k)

            def result(ref: Any) -> EpisodeRun:
                return ray.get(ref)  # type: ignore[no-any-return]

            yield from _in_order(submit, result, ray.cancel, indices, self.workers)
        finally:
            if started:
                ray.shutdown()


def _in_order(submit: Callable[[int], H], result: Callable[[H], EpisodeRun], cancel: Callable[[H], Any],
              indices: range, workers: int) -> Iterator[EpisodeRun]:
    """Keep ``AHEAD * workers`` episodes submitted; yield their results in index order.

    If the consumer stops early (an error while writing), episodes not yet started are cancelled.
    """
    todo = iter(indices)
    pending = deque(submit(k) for k in itertools.islice(todo, AHEAD * workers))
    try:
        while pending:
            run = result(pending.popleft())
            pending.extend(submit(k) for k in itertools.islice(todo, 1))
            yield run
    finally:
        for handle in pending:
            cancel(handle)


# In a worker process (or Ray worker): one critic per configuration, built on first use.
_CRITICS: dict[str, Any] = {}


def _episode(plan: Plan, cfg: GenerateConfig, index: int) -> EpisodeRun:
    os.environ.setdefault("LP_NUM_THREADS", "1")  # one rasteriser thread: a worker is one core
    key = repr(cfg.critic)
    if key not in _CRITICS:
        _CRITICS[key] = build_critic(cfg)
    return sample_episode(plan, index, cfg, _CRITICS[key])
