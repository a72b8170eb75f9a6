"""How a policy reads quaternions: continuous, sign-blind rotation-matrix columns by default."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch

from conftest import tiny
from vcage.errors import ConfigError
from vcage.policy.checkpoint import load_checkpoint
from vcage.policy.config import TrainConfig
from vcage.policy.dataset import FeatureSpec, load_training_data
from vcage.policy.encoding import VectorEncoder, position_starts, quaternion_starts, rot6d
from vcage.policy.inference import PolicyRunner
from vcage.policy.train import train

EE_NAMES = ("x", "y", "z", "qw", "qx", "qy", "qz")
FEATURES = (FeatureSpec("observation.state", 2, ("joint1", "gripper_width")),
            FeatureSpec("observation.ee_pose", 7, EE_NAMES),
            FeatureSpec("observation.environment_state", 14,
                        tuple(f"{o}.{n}" for o in ("bell", "pad") for n in EE_NAMES)))


def test_quaternions_are_found_by_their_element_names() -> None:
    assert quaternion_starts(EE_NAMES) == [3]
    assert quaternion_starts(FEATURES[2].names) == [3, 10]
    assert quaternion_starts(("joint1", "joint2")) == [] and quaternion_starts(None) == []
    # a run whose prefixes differ, or whose prefix is not an object name, is not a quaternion
    assert quaternion_starts(("a.qw", "b.qx", "a.qy", "a.qz")) == []
    assert quaternion_starts(("xqw", "xqx", "xqy", "xqz")) == []
    assert quaternion_starts(("qx", "qw", "qy", "qz")) == []


def test_rot6d_is_the_rotation_matrix_first_two_columns_and_blind_to_the_sign() -> None:
    rng = np.random.default_rng(0)
    q = rng.normal(size=(50, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    np.testing.assert_allclose(rot6d(q), rot6d(-q), atol=1e-12)
    half = np.pi / 6  # a turn of 60 degrees about z
    np.testing.assert_allclose(rot6d(np.array([np.cos(half), 0, 0, np.sin(half)])),
                               [0.5, np.sqrt(3) / 2, 0, -np.sqrt(3) / 2, 0.5, 0], atol=1e-12)


def test_a_gripper_pointing_down_reads_the_same_across_the_stored_sign_flip() -> None:
    """The end effector's stored quaternion jumps from (0, 1, 0, 0) to (0, -1, 0, 0) when w crosses
    zero; the encoded input moves by the small rotation between the two frames only."""
    encoder = VectorEncoder(FEATURES[1:2], "rot6d")
    before = np.array([0.4, 0.0, 1.1, 0.001, 1.0, 0.0, 0.01], dtype=np.float32)
    # a frame later w is -0.001: stored with w >= 0, i.e. negated
    after = np.array([0.4, 0.0, 1.1, 0.001, -1.0, 0.0, -0.01], dtype=np.float32)
    assert np.abs(before - after).max() == pytest.approx(2.0)
    assert np.abs(encoder(before) - encoder(after)).max() < 0.005
    same = before.copy()
    same[3:] *= -1  # -q: the same pose exactly
    np.testing.assert_allclose(encoder(before), encoder(same), atol=1e-6)


def test_the_encoder_keeps_every_other_value_in_place_and_grows_by_two_per_quaternion() -> None:
    encoder = VectorEncoder(FEATURES, "rot6d")
    raw = np.arange(23, dtype=np.float32) / 23 + 0.1
    out = encoder(np.stack([raw, raw]))
    assert encoder.raw_size == 23 and encoder.size == 29 and out.shape == (2, 29) and out.dtype == np.float32
    np.testing.assert_array_equal(out[0, :5], raw[:5])  # state, then the end effector's position
    np.testing.assert_allclose(out[0, 5:11], rot6d(raw[5:9]), rtol=1e-6)
    np.testing.assert_array_equal(out[0, 11:14], raw[9:12])  # the bell's position
    np.testing.assert_array_equal(out[0, 20:23], raw[16:19])  # the pad's position
    passthrough = VectorEncoder(FEATURES, "quaternion")
    assert passthrough.size == 23 and np.array_equal(passthrough(raw), raw)
    with pytest.raises(ValueError, match="expected 23"):
        encoder(raw[:-1])
    with pytest.raises(ConfigError, match="rot6d"):
        VectorEncoder(FEATURES, "euler")


def test_the_default_is_rot6d_and_checkpoints_written_before_the_choice_read_quaternions(
        dataset: Path, tmp_path: Path) -> None:
    assert TrainConfig().rotations == "rot6d"
    given = TrainConfig().to_dict()
    del given["rotations"]  # a configuration that does not choose gets the default
    assert TrainConfig.from_dict(given).rotations == "rot6d"
    with pytest.raises(ConfigError, match="unknown rotations"):
        TrainConfig(rotations="euler")
    path = train(dataset, tmp_path / "run", tiny("mlp", steps=2, checkpoint_every=2,
                                                 rotations="quaternion")).checkpoint
    payload = torch.load(path, weights_only=True)
    del payload["config"]["rotations"]  # as checkpoints were written before the choice
    torch.save(payload, path)
    old = load_checkpoint(path)
    assert old["config"]["rotations"] == "quaternion"
    assert PolicyRunner(old).encoder.size == 22  # its weights take the 22 stored values


def test_training_data_carries_the_encoded_observations(dataset: Path) -> None:
    encoded = load_training_data(dataset, tiny("mlp"))
    raw = load_training_data(dataset, tiny("mlp", rotations="quaternion"))
    assert raw.obs.shape[1] == 22 and encoded.obs.shape[1] == 26  # two quaternions, 4 -> 6 values each
    encoder = VectorEncoder(raw.obs_features, "rot6d")
    np.testing.assert_allclose(encoded.obs, encoder(raw.obs), rtol=1e-6)


def test_object_positions_are_found_by_their_element_names() -> None:
    assert position_starts(EE_NAMES) == [("", 0)]
    assert position_starts(FEATURES[2].names) == [("bell.", 0), ("pad.", 7)]
    assert position_starts(("a.x", "b.y", "a.z")) == [] and position_starts(("px", "py", "pz")) == []
    assert position_starts(None) == []


def test_relative_inputs_append_each_object_position_minus_the_tools() -> None:
    rng = np.random.default_rng(1)
    raw = rng.normal(size=(5, 23)).astype(np.float32)
    plain = VectorEncoder(FEATURES, "rot6d")
    relative = VectorEncoder(FEATURES, "rot6d", relative=True)
    assert relative.size == plain.size + 6
    encoded = relative(raw)
    np.testing.assert_array_equal(encoded[:, :plain.size], plain(raw))  # the plain inputs come first
    tool, bell, pad = raw[:, 2:5], raw[:, 9:12], raw[:, 16:19]
    np.testing.assert_allclose(encoded[:, plain.size:plain.size + 3], bell - tool, atol=1e-6)
    np.testing.assert_allclose(encoded[:, plain.size + 3:], pad - tool, atol=1e-6)
    assert not relative.rotation_mask()[plain.size:].any()  # offsets are positions
    with pytest.raises(ValueError, match="decodes nothing"):
        relative.decode(encoded)


def test_relative_inputs_without_the_tool_or_an_object_are_refused() -> None:
    with pytest.raises(ConfigError, match="found 0 tool and 2 object positions"):
        VectorEncoder([FEATURES[0], FEATURES[2]], "rot6d", relative=True)
    with pytest.raises(ConfigError, match="found 1 tool and 0 object positions"):
        VectorEncoder(FEATURES[:2], "rot6d", relative=True)
    with pytest.raises(ConfigError, match="relative_objects must be true or false"):
        TrainConfig(relative_objects="yes")  # type: ignore[arg-type]


def test_a_policy_with_relative_inputs_trains_and_acts_on_the_offsets(dataset: Path, tmp_path: Path) -> None:
    config = tiny("mlp", steps=2, checkpoint_every=2, relative_objects=True)
    data = load_training_data(dataset, config)
    plain = load_training_data(dataset, tiny("mlp", steps=2, checkpoint_every=2))
    assert data.obs.shape[1] == plain.obs.shape[1] + 3  # one object (the block)
    runner = PolicyRunner(load_checkpoint(train(dataset, tmp_path / "run", config).checkpoint))
    assert runner.encoder.relative and runner.encoder.size == data.obs.shape[1]
    obs = {"observation.state": np.zeros(8, np.float32),
           "observation.ee_pose": np.array([0.1, 0.2, 0.3, 1, 0, 0, 0], np.float32),
           "observation.environment_state": np.array([0.5, -0.2, 0.3, 1, 0, 0, 0], np.float32)}
    np.testing.assert_allclose(runner.observation_vector(obs)[-3:], [0.4, -0.4, 0.0], atol=1e-6)
    assert runner.act(obs).shape == (8,)
