"""Evaluation episodes that depend on nothing run before them, so that worker processes can share
them: the same episodes (scenes, steps, outcomes) from one process or several."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

from conftest import tiny
from vcage.data import DatasetReader
from vcage.errors import ConfigError
from vcage.pipeline.evaluation import eval_seed, make_env
from vcage.policy.checkpoint import load_checkpoint
from vcage.policy.errors import PolicyError
from vcage.policy.evaluate import evaluate
from vcage.policy.inference import PolicyRunner
from vcage.policy.rollout import rollout
from vcage.policy.train import train

pytestmark = pytest.mark.slow  # evaluation rollouts in worker processes


@pytest.fixture(scope="module")
def diffusion_run(generated: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    return train(generated, tmp_path_factory.mktemp("run"), tiny("diffusion", steps=2, checkpoint_every=2,
                                                                  batch_size=8)).checkpoint


class Recorder(gym.Wrapper):
    """Keeps every action the policy took."""

    def __init__(self, env: gym.Env) -> None:
        super().__init__(env)
        self.actions: list[np.ndarray] = []

    def step(self, action: Any) -> Any:
        self.actions.append(np.asarray(action).copy())
        return self.env.step(action)


def test_an_episode_is_the_same_whatever_ran_before_it(generated: Path, diffusion_run: Path) -> None:
    config = DatasetReader(generated).config
    runner = PolicyRunner(load_checkpoint(diffusion_run), seed=0)
    env = Recorder(make_env(config, seed=5, max_steps=9))
    fresh = rollout(runner, env, 5, episode=2)
    alone = list(env.actions)
    for k in (0, 1):  # other episodes first: they draw noise and move the env's episode counter
        rollout(runner, env, 5, episode=k)
    env.actions.clear()
    again = rollout(runner, env, 5, episode=2)
    assert again == fresh and fresh.scene_seed == eval_seed(5, 2, 0)
    np.testing.assert_array_equal(np.stack(env.actions), np.stack(alone))
    other = rollout(runner, env, 5, episode=1)
    assert other.scene_seed != fresh.scene_seed
    env.close()


def test_two_workers_give_the_episodes_of_one(generated: Path, diffusion_run: Path) -> None:
    one = evaluate(diffusion_run, 3, seed=7, max_steps=6, threads=1)
    done: list[int] = []
    two = evaluate(diffusion_run, 3, seed=7, max_steps=6, workers=2, progress=lambda k, n, r: done.append(k))
    assert two.episodes == one.episodes and done == [1, 2, 3]
    assert [e.scene_seed for e in one.episodes] == [eval_seed(7, k, 0) for k in range(3)]


def test_workers_and_batches_need_an_environment_that_starts_episodes_by_index(diffusion_run: Path,
                                                                               generated: Path) -> None:
    config = DatasetReader(generated).config

    def opaque(cfg: dict[str, Any], *, seed: int, max_steps: int | None = None,
               action: str = "action") -> gym.Env:
        return _NoIndex(make_env(cfg, seed=seed, max_steps=max_steps))

    with pytest.raises(PolicyError, match="--workers 1"):
        evaluate(diffusion_run, 2, env_config=config, make_env=opaque, workers=2, max_steps=4)
    with pytest.raises(PolicyError, match="--workers"):
        evaluate(diffusion_run, 2, workers=0)
    with pytest.raises(PolicyError, match="--batch 1"):
        evaluate(diffusion_run, 2, env_config=config, make_env=opaque, batch=2, max_steps=4)
    with pytest.raises(PolicyError, match="--batch must be a positive integer"):
        evaluate(diffusion_run, 2, batch=0)
    env = make_env(config, seed=1, max_steps=4)
    with pytest.raises(ConfigError, match="episode index"):
        env.reset(options={"episode": -1})
    env.close()


class _NoIndex(gym.Wrapper):
    """An environment that does not say it can start episode k directly."""

    @property
    def unwrapped(self) -> gym.Env:
        return self


def test_batched_blocks_give_the_same_episodes_from_one_worker_or_two(generated: Path,
                                                                      diffusion_run: Path) -> None:
    one = evaluate(diffusion_run, 5, seed=7, max_steps=6, threads=1, batch=2)  # blocks [0, 1] [2, 3] [4]
    done: list[int] = []
    two = evaluate(diffusion_run, 5, seed=7, max_steps=6, workers=2, batch=2,
                   progress=lambda k, n, r: done.append(k))
    assert two.episodes == one.episodes and sorted(done) == [1, 2, 3, 4, 5]
    assert [e.scene_seed for e in one.episodes] == [eval_seed(7, k, 0) for k in range(5)]
    alone = evaluate(diffusion_run, 5, seed=7, max_steps=6, threads=1)
    assert [e.scene_seed for e in alone.episodes] == [e.scene_seed for e in one.episodes]
    assert all(e.steps == 6 for e in one.episodes)  # every episode of a block runs to its own end


def test_a_block_samples_each_episodes_chunk_from_its_own_noise(generated: Path, diffusion_run: Path) -> None:
    """Stepped beside another episode, an episode's actions are its actions alone (to float32
    rounding of the batched arithmetic), not those of its neighbour's noise."""
    from vcage.policy.rollout import rollout_block

    config = DatasetReader(generated).config
    payload = load_checkpoint(diffusion_run)
    solo = Recorder(make_env(config, seed=3, max_steps=9))
    rollout(PolicyRunner(payload), solo, 3, episode=1)
    pair = [Recorder(make_env(config, seed=3, max_steps=9)) for _ in range(2)]
    results = rollout_block([PolicyRunner(payload), PolicyRunner(payload)], pair, 3, [0, 1])
    np.testing.assert_allclose(np.stack(pair[1].actions), np.stack(solo.actions), atol=1e-4)
    assert not np.allclose(np.stack(pair[0].actions), np.stack(pair[1].actions), atol=1e-3)
    assert [r.scene_seed for r in results] == [eval_seed(3, 0, 0), eval_seed(3, 1, 0)]
    for env in (solo, *pair):
        env.close()

