"""The rollout loop: observation window, action chunking, statistics of the episodes."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
import torch
from gymnasium import spaces

from conftest import EE, ENV, FPS, STATE, tiny
from vcage.policy.checkpoint import load_checkpoint
from vcage.policy.evaluate import evaluate
from vcage.policy.inference import PolicyRunner
from vcage.policy.metrics import subtask_reached, wilson_interval
from vcage.policy.train import train

SIZES = {STATE: 8, EE: 7, ENV: 7}


@pytest.fixture(scope="module")
def checkpoint(dataset: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    return train(dataset, tmp_path_factory.mktemp("run"), tiny("mlp", steps=4, checkpoint_every=4)).checkpoint


class CountingEnv(gym.Env):
    """Observations count the steps; episode k succeeds at its subtasks after 5 steps each when
    ``k`` is in ``winners``, else is truncated after ``max_steps``."""

    def __init__(self, winners: set[int], subtasks: int = 2, max_steps: int = 12) -> None:
        self.observation_space = spaces.Dict({k: spaces.Box(-1e3, 1e3, shape=(n,)) for k, n in SIZES.items()})
        self.action_space = spaces.Box(-10, 10, shape=(8,))
        self.metadata = {"render_fps": FPS}
        self.winners, self.subtasks, self.max_steps = winners, subtasks, max_steps
        self.episode, self.resets = -1, []

    def _obs(self) -> dict[str, np.ndarray]:
        return {k: np.full(n, float(self.t), dtype=np.float32) for k, n in SIZES.items()}

    def reset(self, *, seed: int | None = None, options: Any = None) -> Any:
        self.resets.append(seed)
        self.episode, self.t, self.done = self.episode + 1, 0, 0
        return self._obs(), {}

    def step(self, action: np.ndarray) -> Any:
        assert action.shape == (8,) and np.isfinite(action).all()
        self.t += 1
        if self.episode in self.winners and self.t % 5 == 0:
            self.done += 1
        info = {"success": self.done == self.subtasks, "subtasks_done": self.done,
                "subtasks": self.subtasks, "progress": self.done / self.subtasks}
        return self._obs(), 0.0, info["success"], self.t >= self.max_steps, info


def test_the_runner_predicts_every_eight_steps_from_a_two_frame_window(checkpoint: Path) -> None:
    runner = PolicyRunner(load_checkpoint(checkpoint))
    seen: list[torch.Tensor] = []
    chunk = torch.arange(16 * 8, dtype=torch.float32).reshape(1, 16, 8) / 100

    def predict_from(obs: torch.Tensor, noise: torch.Tensor, subtask: torch.Tensor | None) -> torch.Tensor:
        seen.append(obs.clone())
        assert noise.shape == (1, 16, 8) and subtask is None  # an unconditioned policy gets no subtask
        return chunk

    runner.model.predict_from = predict_from  # type: ignore[method-assign]
    env = CountingEnv(set())
    obs, _ = env.reset()
    actions = []
    for _ in range(17):
        actions.append(runner.act(obs))
        obs, *_ = env.step(actions[-1])
    assert len(seen) == 3  # steps 0, 8 and 16
    first = seen[0][0]
    # the first frame, repeated; two quaternions read as 6 rotation-matrix values each
    assert first.shape == (2, 26) and torch.equal(first[0], first[1])
    norm, encode = runner.obs_norm, runner.encoder
    torch.testing.assert_close(seen[1][0], torch.from_numpy(np.stack(
        [norm.normalize(encode(np.full(22, 7.0))), norm.normalize(encode(np.full(22, 8.0)))])))
    expected = runner.action_norm.unnormalize(chunk[0, 1:9].numpy())  # from the current frame on
    np.testing.assert_allclose(np.stack(actions[:8]), expected, rtol=1e-6)
    np.testing.assert_allclose(actions[8], expected[0], rtol=1e-6)
    runner.reset()
    runner.act(obs)
    assert len(seen) == 4 and torch.equal(seen[3][0][0], seen[3][0][1])


def test_a_strided_runner_reads_every_kth_observation_back_from_the_current_one(dataset: Path,
                                                                                tmp_path: Path) -> None:
    config = tiny("mlp", steps=1, checkpoint_every=1, n_obs_steps=3, obs_stride=4, horizon=16)
    runner = PolicyRunner(load_checkpoint(train(dataset, tmp_path / "run", config).checkpoint))
    seen: list[torch.Tensor] = []

    def predict_from(obs: torch.Tensor, noise: torch.Tensor, subtask: torch.Tensor | None) -> torch.Tensor:
        seen.append(obs.clone())
        return torch.zeros(1, 16, 8)

    runner.model.predict_from = predict_from  # type: ignore[method-assign]
    env = CountingEnv(set(), max_steps=30)
    obs, _ = env.reset()
    for _ in range(17):  # chunks at steps 0, 8 and 16, whose observations count 0, 8 and 16
        obs, *_ = env.step(runner.act(obs))
    assert len(seen) == 3 and seen[0].shape == (1, 3, 26)
    norm, encode = runner.obs_norm, runner.encoder

    def frames(*counts: float) -> torch.Tensor:
        return torch.from_numpy(np.stack([norm.normalize(encode(np.full(22, c))) for c in counts]))

    torch.testing.assert_close(seen[0][0], frames(0, 0, 0))
    torch.testing.assert_close(seen[1][0], frames(0, 4, 8))  # the start repeated before frame 0
    torch.testing.assert_close(seen[2][0], frames(8, 12, 16))


def test_evaluate_rolls_out_every_episode_and_counts_what_the_environment_reports(checkpoint: Path) -> None:
    envs: list[CountingEnv] = []

    def make_env(config: dict[str, Any], *, seed: int, max_steps: int | None = None,
                 action: str = "action") -> gym.Env:
        envs.append(CountingEnv({0, 2}, max_steps=max_steps or 12))
        return envs[-1]

    done: list[int] = []
    result = evaluate(checkpoint, 4, seed=3, make_env=make_env, progress=lambda k, n, r: done.append(k))
    assert done == [1, 2, 3, 4] and envs[0].resets == [3, None, None, None]
    assert [e.success for e in result.episodes] == [True, False, True, False]
    assert [e.steps for e in result.episodes] == [10, 12, 10, 12]
    assert result.success_rate == 0.5 and result.subtask_progress == [0.5, 0.5]
    assert result.interval == pytest.approx(wilson_interval(2, 4))
    assert result.rollouts_per_minute > 0
    record = result.to_dict()
    assert {"success_rate", "wilson95", "subtask_progress", "rollouts_per_minute",
            "per_episode"} <= set(record)


class LurchingEnv(CountingEnv):
    """A :class:`CountingEnv` that steps a real MuJoCo world (one block) with each step; in the
    episodes ``lurch`` the block is flung at 1e6 m/s before step 3, and the world's stability check
    raises as the env's contract says (a policy driving objects an unchecked scene fused together)."""

    episode_option = True  # starts episode k when asked (options={"episode": k}), as GoalEnv does

    def __init__(self, winners: set[int], lurch: set[int]) -> None:
        from vcage.scene.compose import compose
        from vcage.scene.spec import ObjectSpec, SceneSpec

        super().__init__(winners)
        self.lurch = lurch
        self.world = compose(SceneSpec(objects=(ObjectSpec("a", "block", (0.5, 0.0)),))).make_world()

    def reset(self, *, seed: int | None = None, options: Any = None) -> Any:
        self.world.reset()
        out = super().reset(seed=seed, options=options)
        self.episode = options["episode"]
        return out

    def step(self, action: np.ndarray) -> Any:
        if self.episode in self.lurch and self.t == 2:
            self.world.data.qvel[self.world.model.joint("a/free").dofadr[0]] = 1e6
        self.world.step()
        return super().step(action)


@pytest.mark.parametrize("batch", [1, 4])
def test_an_episode_whose_physics_fails_ends_as_a_failure_and_the_evaluation_goes_on(checkpoint: Path,
                                                                                     batch: int) -> None:
    """Episode 1 would succeed but its physics fails at step 3: it counts as a failure that says why,
    after the steps it took; the episodes around it are rolled out as if it had not happened."""

    def make_env(config: dict[str, Any], *, seed: int, max_steps: int | None = None,
                 action: str = "action") -> gym.Env:
        return LurchingEnv({0, 1, 2}, lurch={1})

    result = evaluate(checkpoint, 4, seed=3, make_env=make_env, batch=batch)
    assert [e.success for e in result.episodes] == [True, False, True, False]
    assert [e.steps for e in result.episodes] == [10, 3, 10, 12]
    assert [e.unstable is not None for e in result.episodes] == [False, True, False, False]
    assert "simulation unstable at t=0.150s: joint 'a/free'" in (result.episodes[1].unstable or "")
    assert result.unstable == 1 and result.to_dict()["unstable"] == 1
    assert result.success_rate == 0.5


def test_wilson_intervals_and_subtask_shares() -> None:
    assert wilson_interval(0, 2) == pytest.approx((0.0, 0.6576), abs=1e-4)
    assert wilson_interval(5, 10) == pytest.approx((0.2366, 0.7634), abs=1e-4)
    assert wilson_interval(10, 10) == pytest.approx((0.7225, 1.0), abs=1e-4)
    assert wilson_interval(0, 0) == (0.0, 1.0)
    assert subtask_reached([0, 1, 3, 2], 3) == [0.75, 0.5, 0.25]


def test_torch_is_imported_by_neither_vcage_nor_the_cli() -> None:
    code = "import sys, vcage, vcage.cli, vcage.policy; print('torch' in sys.modules)"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "False"
