"""TaskEnv: atomic tasks as Gymnasium environments, on real MuJoCo scenes (no mocks)."""

from __future__ import annotations

import subprocess
import sys
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from vcage.envs import env_id, register_envs
from vcage.tasks import run_episode
from vcage.tasks.env import TaskEnv

TASK = "stack_blocks_two"


@pytest.fixture(scope="module", autouse=True)
def registered() -> list[str]:
    return register_envs()


def test_register_envs_is_idempotent_and_covers_every_task(registered: list[str]) -> None:
    from vcage.tasks import TASKS

    assert register_envs() == registered  # a second call neither raises nor changes anything
    assert registered == [env_id(name) for name in TASKS.names()]
    assert env_id(TASK) == "vcage/stack_blocks_two-v0"
    assert gym.spec(env_id(TASK)).kwargs == {"task": TASK}


@pytest.mark.slow
def test_a_bare_import_registers_the_environments_in_a_fresh_interpreter() -> None:
    code = ("import gymnasium as gym, sys; import vcage; "
            "assert 'mujoco' not in sys.modules, 'registration must not load the simulator'; "
            f"env = gym.make({env_id(TASK)!r}); obs, info = env.reset(seed=0); print(info['instruction'])")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == run_episode(TASK, 0).instruction
    # gymnasium's module:id form imports vcage itself
    code = f"import gymnasium as gym; gym.make('vcage:{env_id(TASK)}')"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr


def test_gymnasium_make_and_check_env() -> None:
    env = gym.make(env_id(TASK))
    try:
        assert isinstance(env.unwrapped, TaskEnv)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            check_env(env.unwrapped)
        # The one warning allowed: check_env recommends a normalised [-1, 1] action space, but the
        # action is deliberately the expert's absolute joint targets (bounded by the joint limits).
        messages = [str(w.message) for w in caught]
        unexpected = [m for m in messages if "symmetric and normalized space" not in m]
        assert not unexpected, unexpected
    finally:
        env.close()


def test_reset_with_a_seed_is_deterministic() -> None:
    env = gym.make(env_id(TASK))
    try:
        obs_1, info_1 = env.reset(seed=3)
        obs_2, info_2 = env.reset(seed=3)
        assert info_1 == info_2 and info_1["seed"] == 3 and info_1["instruction"]
        assert obs_1.keys() == obs_2.keys()
        for key in obs_1:
            np.testing.assert_array_equal(obs_1[key], obs_2[key])
        assert obs_1["object_poses"].shape == (2, 7) and obs_1["qpos"].dtype == np.float32
        obs_3, _ = env.reset(seed=4)
        assert not np.array_equal(obs_1["object_poses"], obs_3["object_poses"])
    finally:
        env.close()


def test_replaying_the_expert_recording_succeeds() -> None:
    seed = 1
    episode = run_episode(TASK, seed)
    assert episode.success
    actions = np.asarray(episode.recording.action)
    assert actions.shape[1] == 8
    env = gym.make(env_id(TASK), max_steps=len(actions) + 10)
    try:
        obs, info = env.reset(seed=seed)
        assert info["instruction"] == episode.instruction
        np.testing.assert_allclose(obs["qpos"], episode.recording.qpos[0], atol=1e-6)
        terminated = truncated = False
        rewards = []
        for action in actions:
            obs, reward, terminated, truncated, info = env.step(action.astype(np.float32))
            rewards.append(reward)
            if terminated or truncated:
                break
        assert terminated and not truncated
        assert reward == 1.0 and info["success"] and info["is_success"]
        hold = env.get_wrapper_attr("hold_steps")
        assert rewards[-hold:] == [1.0] * hold
        with pytest.raises(gym.error.ResetNeeded):  # a terminated episode is over
            env.step(actions[-1].astype(np.float32))
    finally:
        env.close()


def test_camera_images_and_render() -> None:
    env = TaskEnv(TASK, cameras=("front", "panda/wrist"), image_size=(48, 64),
                  render_mode="rgb_array")
    try:
        assert isinstance(env.observation_space, gym.spaces.Dict)
        images = env.observation_space["images"]
        assert isinstance(images, gym.spaces.Dict) and images["front"].shape == (48, 64, 3)
        obs, _ = env.reset(seed=0)
        assert obs in env.observation_space
        for cam in ("front", "panda/wrist"):
            img = obs["images"][cam]
            assert img.shape == (48, 64, 3) and img.dtype == np.uint8 and img.std() > 0
        obs, *_ = env.step(env.action_space.sample())
        assert obs["images"]["front"].shape == (48, 64, 3)
        frame = env.render()
        assert frame is not None and frame.shape == (48, 64, 3) and frame.dtype == np.uint8
    finally:
        env.close()
    env.close()  # closing twice is allowed


def test_out_of_range_action_is_clipped() -> None:
    env = TaskEnv(TASK)
    try:
        env.reset(seed=0)
        world = env.world
        assert world is not None
        assert isinstance(env.action_space, gym.spaces.Box)
        high, low = env.action_space.high, env.action_space.low
        limits = world.robot.arm_limits
        action = np.append(limits[:, 1] + 0.5, 3.0)
        action[3] = limits[3, 0] - 5.0  # below the lower limit on one joint
        obs, reward, terminated, truncated, _ = env.step(action)
        ctrl = world.data.ctrl
        expected = np.clip(action, low, high)
        np.testing.assert_allclose(ctrl[world.robot.arm_act], expected[:7], rtol=1e-6)
        np.testing.assert_allclose(ctrl[world.robot.finger_act], 0.04)  # gripper clipped to 1 (open)
        assert reward == 0.0 and not terminated and not truncated
        assert obs in env.observation_space
        with pytest.raises(ValueError):
            env.step(np.zeros(7))
    finally:
        env.close()


def test_step_before_reset_and_truncation() -> None:
    env = TaskEnv(TASK, max_steps=3)
    try:
        with pytest.raises(gym.error.ResetNeeded):
            env.step(env.action_space.sample())
        obs, _ = env.reset(seed=0)
        hold = np.append(obs["qpos"], 1.0)
        flags = [env.step(hold)[3] for _ in range(3)]
        assert flags == [False, False, True]
    finally:
        env.close()


def test_simulation_error_propagates_from_step() -> None:
    from vcage.config import SimConfig
    from vcage.errors import SimulationError

    env = TaskEnv(TASK)
    try:
        env.reset(seed=0)
        world = env.world
        assert world is not None and isinstance(env.action_space, gym.spaces.Box)
        # A real instability check with an absurdly low velocity limit: any motion is "unstable".
        world.sim = SimConfig(max_qvel=1e-9)
        with pytest.raises(SimulationError):
            env.step(env.action_space.high)
        with pytest.raises(gym.error.ResetNeeded):  # the exploded episode cannot go on
            env.step(env.action_space.high)
        env.reset(seed=0)  # a reset builds a fresh world and the environment is usable again
        env.step(env.action_space.high)
    finally:
        env.close()
