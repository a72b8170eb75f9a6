"""Normalisation from the dataset's frames: ranges, round trips, constant dimensions."""

from __future__ import annotations

import numpy as np
import pytest

from vcage.errors import ConfigError
from vcage.policy.normalize import Normalizer


def frames() -> np.ndarray:
    rng = np.random.default_rng(3)
    x = rng.normal([1.0, -5.0, 100.0], [0.1, 3.0, 20.0], size=(200, 3))
    x[:, 1] = 7.0  # a constant dimension
    return x.astype(np.float32)


def test_min_max_maps_the_frames_to_minus_one_one_and_back() -> None:
    x = frames()
    norm = Normalizer.fit(x, "min_max")
    y = norm.normalize(x)
    assert y[:, [0, 2]].min(axis=0) == pytest.approx([-1, -1], abs=1e-6)
    assert y[:, [0, 2]].max(axis=0) == pytest.approx([1, 1], abs=1e-6)
    assert (y[:, 1] == 0).all()  # constant: centred, not divided by zero
    np.testing.assert_allclose(norm.unnormalize(y), x, rtol=1e-6, atol=1e-5)


def test_mean_std_standardises_and_round_trips_through_its_stored_form() -> None:
    x = frames()
    norm = Normalizer.from_dict(Normalizer.fit(x, "mean_std").to_dict())
    y = norm.normalize(x)
    np.testing.assert_allclose(y[:, [0, 2]].mean(axis=0), 0, atol=1e-5)
    np.testing.assert_allclose(y[:, [0, 2]].std(axis=0), 1, atol=1e-4)
    assert np.isfinite(y).all() and (y[:, 1] == 0).all()
    np.testing.assert_allclose(norm.unnormalize(y), x, rtol=1e-6, atol=1e-5)


def test_unknown_modes_and_empty_frames_are_refused() -> None:
    with pytest.raises(ConfigError, match="min_max, mean_std"):
        Normalizer.fit(frames(), "zscore")
    with pytest.raises(ConfigError, match="T >= 1"):
        Normalizer.fit(np.zeros((0, 3)), "min_max")


def test_a_floor_keeps_a_dimension_that_barely_moves_from_being_stretched() -> None:
    x = frames()
    x[:, 0] = 0.3 + np.linspace(0, 1.5e-4, len(x))  # a pad's tilt in clean demonstrations
    bare, floored = Normalizer.fit(x, "min_max"), Normalizer.fit(x, "min_max", floor=0.01)
    deviation = x[:1].copy()
    deviation[0, 0] += 1e-3  # one milliradian off in closed loop
    assert abs(bare.normalize(deviation)[0, 0]) > 10  # far outside what the network was trained on
    assert abs(floored.normalize(deviation)[0, 0]) < 0.2
    assert floored.scale[2] == bare.scale[2]  # a dimension that moves more keeps its own range
    assert floored.scale[1] == pytest.approx(0.01)  # a constant one gets the floor, not 1
    np.testing.assert_allclose(floored.unnormalize(floored.normalize(x)), x, rtol=1e-6, atol=1e-5)
    with pytest.raises(ConfigError, match="floor"):
        Normalizer.fit(x, "min_max", floor=-1.0)


def test_rotation_columns_get_their_own_floor() -> None:
    from vcage.policy import TrainConfig
    from vcage.policy.dataset import FeatureSpec
    from vcage.policy.encoding import VectorEncoder
    from vcage.policy.train import floors

    pose = FeatureSpec("observation.ee_pose", 7, ("x", "y", "z", "qw", "qx", "qy", "qz"))
    config = TrainConfig(norm_floor=0.01, rotation_floor=0.05)
    encoder = VectorEncoder([pose], config.rotations)
    np.testing.assert_array_equal(floors(encoder, config), [0.01] * 3 + [0.05] * 6)
    with pytest.raises(ConfigError, match="norm_floor"):
        TrainConfig(norm_floor=-0.1)
