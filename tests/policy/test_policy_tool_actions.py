"""Policies that predict the tool's pose (``action.ee_pose``): the quaternion encoded for training
and decoded to a unit quaternion for the environment, which turns the pose into joint targets by IK."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from conftest import tiny
from vcage.cli import app
from vcage.data import DatasetReader
from vcage.errors import ConfigError
from vcage.pipeline.evaluation import make_env
from vcage.pipeline.features import ACTION, ACTION_EE, ACTIONS
from vcage.policy.checkpoint import load_checkpoint
from vcage.policy.config import ACTIONS as POLICY_ACTIONS
from vcage.policy.config import TrainConfig
from vcage.policy.dataset import FeatureSpec, load_training_data
from vcage.policy.encoding import VectorEncoder, rot6d
from vcage.policy.errors import EnvironmentMismatchError, MissingFeatureError
from vcage.policy.evaluate import check_compatible
from vcage.policy.inference import PolicyRunner

TOOL = FeatureSpec(ACTION_EE, 8, ("x", "y", "z", "qw", "qx", "qy", "qz", "gripper"))


def unit_quaternions(n: int, seed: int = 0) -> np.ndarray:
    q = np.random.default_rng(seed).normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    q[q[:, 0] < 0] *= -1
    return q


def test_a_tool_action_is_encoded_with_rot6d_and_decoded_to_the_same_pose() -> None:
    encoder = VectorEncoder([TOOL], "rot6d")
    rng = np.random.default_rng(1)
    raw = np.column_stack([rng.normal(size=(40, 3)), unit_quaternions(40), rng.uniform(size=40)])
    encoded = encoder(raw)
    assert encoder.size == 10 and encoded.shape == (40, 10)
    np.testing.assert_allclose(encoded[:, 3:9], rot6d(raw[:, 3:7]), atol=1e-6)
    np.testing.assert_allclose(encoder.decode(encoded), raw, atol=1e-6)
    # what a network outputs is not orthonormal: the nearest rotation, as a unit quaternion, w >= 0
    noisy = encoded + rng.normal(scale=0.05, size=encoded.shape).astype(np.float32)
    decoded = encoder.decode(noisy)
    quats = decoded[:, 3:7]
    np.testing.assert_allclose(np.linalg.norm(quats, axis=1), 1.0, atol=1e-6)
    assert (quats[:, 0] >= 0).all()
    first = noisy[:, 3:6] / np.linalg.norm(noisy[:, 3:6], axis=1, keepdims=True)
    np.testing.assert_allclose(rot6d(quats)[:, :3], first, atol=1e-5)  # the first column is kept
    np.testing.assert_array_equal(decoded[:, [0, 1, 2, 7]], noisy[:, [0, 1, 2, 9]])
    with pytest.raises(ValueError, match="expected 10 encoded"):
        encoder.decode(encoded[:, :8])
    joints = VectorEncoder([FeatureSpec(ACTION, 8, tuple(f"j{i}" for i in range(8)))], "rot6d")
    assert np.array_equal(joints.decode(raw.astype(np.float32)), raw.astype(np.float32))


def test_the_action_is_a_choice_of_the_configuration() -> None:
    assert POLICY_ACTIONS == ACTIONS  # the policy (torch only) names what the environment takes
    assert TrainConfig().action_key == ACTION
    given = TrainConfig().to_dict()
    del given["action_key"]  # checkpoints written before the choice predict joint targets
    assert TrainConfig.from_dict(given).action_key == ACTION
    with pytest.raises(ConfigError, match="unknown action 'torque'"):
        TrainConfig(action_key="torque")
    with pytest.raises(ConfigError, match="other than the actions"):
        TrainConfig(observation_keys=("observation.state", ACTION_EE))


def test_a_dataset_without_tool_actions_names_the_backfill_command(dataset: Path) -> None:
    with pytest.raises(MissingFeatureError, match=rf"no feature '{ACTION_EE}'.*vcage backfill {dataset}"):
        load_training_data(dataset, tiny("mlp", action_key=ACTION_EE))


@pytest.fixture(scope="module")
def tool_run(generated: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("tool") / "run"
    result = CliRunner().invoke(app, ["train", str(generated), "--policy", "mlp", "--out", str(out),
                                      "--steps", "4", "--batch-size", "8", "--action", ACTION_EE,
                                      "--threads", "1"])
    assert result.exit_code == 0, result.output
    return out


def test_a_policy_trained_on_tool_poses_acts_in_tool_poses_in_the_datasets_environment(
        generated: Path, tool_run: Path) -> None:
    data = load_training_data(generated, tiny("mlp", action_key=ACTION_EE))
    assert data.action.shape[1] == 10 and data.action_feature.name == ACTION_EE
    payload = load_checkpoint(tool_run)
    runner = PolicyRunner(payload)
    assert runner.model.action_dim == 10
    config = DatasetReader(generated).config
    env = make_env(config, seed=0, max_steps=12, action=ACTION_EE)
    check_compatible(payload, env)
    obs, _ = env.reset()
    for _ in range(12):
        action = runner.act(obs)
        assert action.shape == (8,) and np.linalg.norm(action[3:7]) == pytest.approx(1.0, abs=1e-5)
        obs, _, terminated, truncated, _ = env.step(action)
    assert truncated
    with pytest.raises(EnvironmentMismatchError, match="takes 'action' as its action, the checkpoint "
                                                       "predicts 'action.ee_pose'"):
        check_compatible(payload, make_env(config, seed=0, max_steps=2))
    result = CliRunner().invoke(app, ["evaluate", str(tool_run), "--episodes", "1", "--max-steps", "16",
                                      "--threads", "1"])
    assert result.exit_code == 0, result.output
    assert "success rate" in result.output
