"""Observation keys that select elements of a feature by name (``observation.state[gripper_width]``):
parsed, read from the dataset, stored in the checkpoint, and read from the environment the same way."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from conftest import EE, STATE, tiny
from vcage.cli import app
from vcage.data import DatasetReader
from vcage.errors import ConfigError
from vcage.pipeline.evaluation import make_env
from vcage.policy.checkpoint import load_checkpoint
from vcage.policy.config import TrainConfig, split_key, split_keys
from vcage.policy.dataset import FeatureSpec, load_training_data
from vcage.policy.errors import EnvironmentMismatchError, MissingFeatureError
from vcage.policy.evaluate import check_compatible
from vcage.policy.inference import PolicyRunner

GRIP = f"{STATE}[gripper_width]"
WRIST_AND_GRIP = f"{STATE}[joint7,gripper_width]"


def test_keys_name_a_feature_or_some_of_its_elements() -> None:
    assert split_key(STATE) == (STATE, None)
    assert split_key(WRIST_AND_GRIP) == (STATE, ("joint7", "gripper_width"))
    assert split_key(f"{STATE}[ joint7 , gripper_width ]") == (STATE, ("joint7", "gripper_width"))
    assert split_keys(f"{EE}, {WRIST_AND_GRIP},{GRIP}") == (EE, WRIST_AND_GRIP, GRIP)
    for bad in (f"{STATE}[]", f"{STATE}[joint7,]", f"{STATE}[joint7,joint7]", f"{STATE}[joint7", "a b"):
        with pytest.raises(ConfigError, match="observation key"):
            split_key(bad)
    with pytest.raises(ConfigError, match="other than the actions"):
        TrainConfig(observation_keys=(EE, "action[gripper]"))
    assert TrainConfig(observation_keys=(EE, GRIP)).observation_keys == (EE, GRIP)


def test_a_selection_reads_the_named_elements_of_the_feature(dataset: Path) -> None:
    data = load_training_data(dataset, tiny("mlp", observation_keys=(EE, WRIST_AND_GRIP)))
    reader = DatasetReader(dataset)
    state = np.concatenate([reader.episode(i).frames[STATE] for i in range(reader.num_episodes)])
    assert data.obs.shape == (reader.total_frames, 9 + 2)  # the pose's quaternion read as rot6d
    np.testing.assert_array_equal(data.obs[:, -2:], state[:, [6, 7]])
    spec = data.obs_features[1]
    assert (spec.name, spec.feature, spec.size, spec.names, spec.indices) == \
        (WRIST_AND_GRIP, STATE, 2, ("joint7", "gripper_width"), (6, 7))
    assert FeatureSpec.from_dict(spec.to_dict()) == spec
    whole = data.obs_features[0]
    assert FeatureSpec.from_dict(whole.to_dict()) == whole and "indices" not in whole.to_dict()
    with pytest.raises(MissingFeatureError, match="has no element\\(s\\) elbow .*joint1, joint2"):
        load_training_data(dataset, tiny("mlp", observation_keys=(f"{STATE}[elbow]",)))


@pytest.fixture(scope="module")
def gripper_run(generated: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("selection") / "run"
    result = CliRunner().invoke(app, ["train", str(generated), "--policy", "mlp", "--out", str(out),
                                      "--steps", "4", "--batch-size", "8", "--threads", "1",
                                      "--obs", f"{EE},{WRIST_AND_GRIP}"])
    assert result.exit_code == 0, result.output
    return out


def test_a_policy_observing_a_selection_reads_the_same_elements_in_the_environment(
        generated: Path, gripper_run: Path) -> None:
    payload = load_checkpoint(gripper_run)
    assert [f["name"] for f in payload["obs_features"]] == [EE, WRIST_AND_GRIP]
    runner = PolicyRunner(payload)
    env = make_env(DatasetReader(generated).config, seed=0, max_steps=8)
    check_compatible(payload, env)
    obs, _ = env.reset()
    vector = runner.observation_vector(obs)
    assert vector.shape == (11,)
    np.testing.assert_array_equal(vector[-2:], np.asarray(obs[STATE], dtype=np.float32)[[6, 7]])
    for _ in range(8):
        obs, *_ = env.step(runner.act(obs))
    moved = copy.deepcopy(payload)  # a checkpoint that expects the elements elsewhere is refused
    moved["obs_features"][1]["names"] = ["joint6", "gripper_width"]
    with pytest.raises(EnvironmentMismatchError, match="reads elements \\['joint6', 'gripper_width'\\]"):
        check_compatible(moved, env)
