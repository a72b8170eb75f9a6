"""Rolling out a policy: episodes stepped one at a time, in blocks, or in worker processes.

An episode starts from the evaluation seed and its index (``options={"episode": k}``) with the sampler
noise of :func:`episode_noise_seed`, so its outcome depends on nothing run before it; a block steps
several episodes together and samples their chunks as one batch (:func:`rollout_block`); worker
processes share whole blocks (:func:`parallel`). An episode whose physics fails ends as a failure
that says so (:attr:`EpisodeResult.unstable`).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import gymnasium as gym
import numpy as np
import torch

from vcage.errors import SimulationError
from vcage.lifetime import die_with_parent
from vcage.policy.checkpoint import load_checkpoint
from vcage.policy.ensemble import TemporalEnsemble
from vcage.policy.errors import PolicyError
from vcage.policy.inference import PolicyRunner, act_together

EnvFactory = Callable[..., gym.Env]  # (config, *, seed, max_steps, action) -> env, as make_env


@dataclass(frozen=True)
class EpisodeResult:
    success: bool
    subtasks_done: int
    subtasks: int
    progress: float
    steps: int
    scene_seed: int | None
    unstable: str | None = None  # why the physics failed, where it ended the episode (a failure)


def episode_noise_seed(seed: int, episode: int) -> int:
    """The seed of the diffusion sampler's noise in evaluation episode ``episode`` of ``seed``."""
    return int(np.random.SeedSequence([seed, episode]).generate_state(1)[0])


def rollout_block(runners: Sequence[PolicyRunner], envs: Sequence[gym.Env], seed: int,
                  episodes: Sequence[int]) -> list[EpisodeResult]:
    """Episodes ``episodes`` stepped together, one per runner and environment: the runners whose
    queue is empty sample their chunks as one batch (:func:`act_together`), and an episode that ends
    leaves the batch. The outcome of an episode depends only on the block it is in (the others'
    observations change what is computed beside it, not the arithmetic of its own chunk, beyond the
    last bits that a batch's size can change)."""
    obs, infos = [], []
    for runner, env, k in zip(runners, envs, episodes, strict=True):
        runner.reset(episode_noise_seed(seed, k))
        observation, info = env.reset(seed=seed, options={"episode": k})
        obs.append(observation)
        infos.append(info)
    results: list[EpisodeResult | None] = [None] * len(episodes)
    steps = [0] * len(episodes)
    live = list(range(len(episodes)))
    while live:
        actions = act_together([runners[i] for i in live], [obs[i] for i in live])
        still = []
        for i, action in zip(live, actions, strict=True):
            try:
                obs[i], _, terminated, truncated, infos[i] = envs[i].step(action)
            except SimulationError as exc:
                results[i] = unstable_result(infos[i], steps[i] + 1, exc)
                continue
            steps[i] += 1
            if terminated or truncated:
                results[i] = episode_result(infos[i], steps[i])
            else:
                still.append(i)
        live = still
    return [r for r in results if r is not None]


def blocks(episodes: int, batch: int) -> list[list[int]]:
    """Episodes 0..episodes-1 in consecutive blocks of ``batch`` (the last may be shorter)."""
    return [list(range(start, min(start + batch, episodes))) for start in range(0, episodes, batch)]


def rollout(runner: PolicyRunner, env: gym.Env, seed: int | None = None,
            episode: int | None = None) -> EpisodeResult:
    """One episode of ``runner`` in ``env`` (reset with ``seed``, if given), to its end.

    With ``episode``, the environment is asked for that episode (``options={"episode": k}``, which
    :class:`~vcage.pipeline.evaluation.GoalEnv` honours) and the sampler's noise restarts from
    :func:`episode_noise_seed`: the episode's outcome then depends on nothing run before it."""
    if episode is None:
        runner.reset()
        obs, info = env.reset(seed=seed)
    else:
        if seed is None:
            raise PolicyError("a rollout of a given episode needs the evaluation seed")
        runner.reset(episode_noise_seed(seed, episode))
        obs, info = env.reset(seed=seed, options={"episode": episode})
    steps, terminated, truncated = 0, False, False
    while not (terminated or truncated):
        try:
            obs, _, terminated, truncated, info = env.step(runner.act(obs))
        except SimulationError as exc:
            return unstable_result(info, steps + 1, exc)
        steps += 1
    return episode_result(info, steps)


def episode_result(info: Mapping[str, Any], steps: int) -> EpisodeResult:
    """What an episode that ended with ``info`` after ``steps`` steps achieved."""
    return EpisodeResult(bool(info.get("success", False)), int(info.get("subtasks_done", 0)),
                         int(info.get("subtasks", 1)), float(info.get("progress", 0.0)), steps,
                         info.get("scene_seed"))


def unstable_result(info: Mapping[str, Any], steps: int, error: SimulationError) -> EpisodeResult:
    """A failed episode whose physics failed at step ``steps``; ``info``: the last the environment
    gave (what it had done before that step)."""
    return replace(episode_result(info, steps), success=False, unstable=str(error))


# -- parallel rollouts: one environment and one policy per worker process ---------------------------
_WORKER: dict[str, Any] = {}


class Blocks:
    """Runs blocks of episodes; a runner and an environment per episode of the largest block so
    far, made when a block first needs them and kept for the next ones."""

    def __init__(self, payload: Mapping[str, Any], factory: EnvFactory, config: dict[str, Any], *, seed: int,
                 max_steps: int | None, device: str, envs: Sequence[gym.Env] = (),
                 ensemble: TemporalEnsemble | None = None) -> None:
        self.payload, self.factory, self.config, self.ensemble = payload, factory, config, ensemble
        self.seed, self.max_steps, self.device = seed, max_steps, device
        self.envs: list[gym.Env] = list(envs)
        self.runners: list[PolicyRunner] = []

    def run(self, group: Sequence[int]) -> list[EpisodeResult]:
        while len(self.runners) < len(group):
            self.runners.append(PolicyRunner(self.payload, device=self.device, seed=self.seed,
                                             ensemble=self.ensemble))
        while len(self.envs) < len(group):
            self.envs.append(self.factory(self.config, seed=self.seed, max_steps=self.max_steps))
        if len(group) == 1:
            return [rollout(self.runners[0], self.envs[0], self.seed, episode=group[0])]
        return rollout_block(self.runners[:len(group)], self.envs[:len(group)], self.seed, group)

    def close(self, keep: int = 0) -> None:
        """Close the environments this made (all but the first ``keep``, which the caller owns)."""
        for env in self.envs[keep:]:
            env.close()


def _start_worker(path: str, factory: EnvFactory, config: dict[str, Any], seed: int,
                  max_steps: int | None, device: str, threads: int, parent: int,
                  ensemble: TemporalEnsemble | None) -> None:
    die_with_parent(parent)
    torch.set_num_threads(threads)
    _WORKER["blocks"] = Blocks(load_checkpoint(path), factory, config, seed=seed, max_steps=max_steps,
                               device=device, ensemble=ensemble)


def _worker_block(group: list[int]) -> list[tuple[int, EpisodeResult]]:
    """The episodes of one block in this worker."""
    return list(zip(group, _WORKER["blocks"].run(group), strict=True))


def parallel(path: str, groups: list[list[int]], workers: int, factory: EnvFactory, config: dict[str, Any],
              *, seed: int, max_steps: int | None, device: str, threads: int,
              progress: Callable[[int, int, EpisodeResult], None] | None,
              ensemble: TemporalEnsemble | None = None) -> list[EpisodeResult]:
    """The blocks of episodes ``groups`` over ``workers`` spawned processes, in episode order."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    episodes = sum(len(g) for g in groups)
    results: dict[int, EpisodeResult] = {}
    context = multiprocessing.get_context("spawn")  # no forked MuJoCo, GL or torch state
    with ProcessPoolExecutor(workers, mp_context=context, initializer=_start_worker,
                             initargs=(path, factory, config, seed, max_steps, device, threads,
                                       os.getpid(), ensemble)) as pool:
        futures = [pool.submit(_worker_block, group) for group in groups]
        for future in as_completed(futures):
            for k, result in future.result():
                results[k] = result
                if progress is not None:
                    progress(len(results), episodes, result)
    return [results[k] for k in range(episodes)]
