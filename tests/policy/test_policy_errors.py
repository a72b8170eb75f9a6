"""Bad input stops training or evaluation with a typed error that says what to do; nothing written
before is lost."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
import torch
from gymnasium import spaces

from conftest import ACTION, EE, ENV, FPS, STATE, tiny, write_dataset
from vcage.errors import ConfigError, DatasetError
from vcage.policy.checkpoint import checkpoints, load_checkpoint
from vcage.policy.config import DiffusionConfig, TrainConfig
from vcage.policy.dataset import load_training_data
from vcage.policy.errors import CheckpointError, EnvironmentMismatchError, MissingFeatureError, PolicyError
from vcage.policy.evaluate import check_compatible, evaluate
from vcage.policy.train import train


@pytest.fixture(scope="module")
def trained(dataset: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("trained")
    return train(dataset, out, tiny("mlp", steps=4, checkpoint_every=4)).checkpoint


def test_a_missing_observation_names_the_feature_and_the_backfill_command(tmp_path: Path) -> None:
    bare = write_dataset(tmp_path / "bare", 2, with_env=False)
    with pytest.raises(MissingFeatureError, match=rf"no feature '{ENV}'.*vcage backfill {bare}"):
        load_training_data(bare, tiny("mlp", observation_keys=(STATE, ENV)))
    no_ee = write_dataset(tmp_path / "no_ee", 2, drop=(EE,))
    with pytest.raises(MissingFeatureError, match=rf"no feature '{EE}'.*vcage backfill"):
        load_training_data(no_ee, tiny("mlp"))
    no_action = write_dataset(tmp_path / "no_action", 2, drop=(ACTION,))
    with pytest.raises(MissingFeatureError, match="no feature 'action'"):
        train(no_action, tmp_path / "run", tiny("mlp"))
    assert not (tmp_path / "run").exists()


def test_without_environment_state_the_defaults_train_and_say_how_to_add_it(tmp_path: Path) -> None:
    bare = write_dataset(tmp_path / "bare", 2, with_env=False)
    summary = train(bare, tmp_path / "run", tiny("mlp", steps=2, checkpoint_every=2))
    assert any(ENV in note and "vcage backfill" in note for note in summary.notes)
    assert [f["name"] for f in load_checkpoint(summary.checkpoint)["obs_features"]] == [STATE, EE]


def test_empty_and_single_episode_datasets_are_refused(dataset: Path, tmp_path: Path) -> None:
    (tmp_path / "empty").mkdir()
    with pytest.raises(DatasetError, match="missing"):
        train(tmp_path / "empty", tmp_path / "run", tiny("mlp"))
    zero = tmp_path / "zero"
    shutil.copytree(dataset, zero)
    info = json.loads((zero / "meta" / "info.json").read_text())
    (zero / "meta" / "info.json").write_text(json.dumps({**info, "total_episodes": 0, "total_frames": 0}))
    with pytest.raises(DatasetError, match="0 episode"):
        train(zero, tmp_path / "run", tiny("mlp"))
    one = write_dataset(tmp_path / "one", 1)
    with pytest.raises(DatasetError, match="1 episode.*at least 2"):
        train(one, tmp_path / "run", tiny("mlp"))
    assert not (tmp_path / "run").exists()


def test_non_finite_frames_are_refused(dataset: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """vcage's writer refuses NaN, but other LeRobot datasets may hold it."""
    from vcage.data.reader import DatasetReader

    real = DatasetReader.episode

    def with_nan(self: DatasetReader, index: int) -> Any:
        ep = real(self, index)
        if index == 1:
            ep.frames[STATE] = ep.frames[STATE].copy()
            ep.frames[STATE][3, 2] = np.inf
        return ep

    monkeypatch.setattr(DatasetReader, "episode", with_nan)
    with pytest.raises(DatasetError, match=f"'{STATE}' of episode 1 holds NaN or infinite"):
        load_training_data(dataset, tiny("mlp"))


@pytest.mark.parametrize("changes, message", [
    ({"policy": "transformer"}, "valid: diffusion, mlp"),
    ({"steps": 0}, "steps must be a positive integer"),
    ({"lr": float("nan")}, "train.lr"),
    ({"n_action_steps": 16}, "must fit in the horizon"),
    ({"horizon": 10}, "divisible by 2"),
    ({"observation_keys": (ACTION,)}, "observation_keys"),
])
def test_invalid_configurations_are_refused(changes: dict[str, Any], message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        TrainConfig(**changes)
    with pytest.raises(ConfigError, match="divisible by n_groups"):
        DiffusionConfig(down_dims=(30,), n_groups=8)


def test_configurations_round_trip_and_unknown_keys_are_refused() -> None:
    config = tiny("diffusion", observation_keys=(STATE,))
    assert TrainConfig.from_dict(json.loads(json.dumps(config.to_dict()))) == config
    with pytest.raises(ConfigError, match="unknown TrainConfig keys"):
        TrainConfig.from_dict({"polcy": "mlp"})


def test_unavailable_devices_are_refused_before_any_work(dataset: Path, tmp_path: Path) -> None:
    for device in ("tpu:7", "cuda:99", "bogus"):
        with pytest.raises(ConfigError, match="device"):
            train(dataset, tmp_path / "run", tiny("mlp"), device=device)
    assert not (tmp_path / "run").exists()


def test_an_output_that_cannot_hold_checkpoints_is_refused(dataset: Path, tmp_path: Path) -> None:
    (tmp_path / "file").write_text("x")
    with pytest.raises(PolicyError, match="is a file"):
        train(dataset, tmp_path / "file", tiny("mlp"))
    with pytest.raises(CheckpointError, match="cannot write the checkpoint"):
        train(dataset, tmp_path / "file" / "run", tiny("mlp", steps=2, checkpoint_every=2))
    assert (tmp_path / "file").read_text() == "x"


def test_missing_and_damaged_checkpoints_are_reported(trained: Path, tmp_path: Path) -> None:
    with pytest.raises(CheckpointError, match="no checkpoint at"):
        load_checkpoint(tmp_path / "nothing.pt")
    with pytest.raises(CheckpointError, match="holds no checkpoint"):
        evaluate(tmp_path, 1)
    cut = tmp_path / "cut.pt"
    cut.write_bytes(trained.read_bytes()[:4000])
    with pytest.raises(CheckpointError, match="not a readable checkpoint"):
        load_checkpoint(cut)
    with pytest.raises(CheckpointError, match="not a readable checkpoint"):
        evaluate(cut, 1)
    foreign = tmp_path / "foreign.pt"
    torch.save({"weights": torch.zeros(3)}, foreign)
    with pytest.raises(CheckpointError, match="not a vcage policy checkpoint"):
        load_checkpoint(foreign)


def test_a_damaged_last_checkpoint_stops_resume_and_is_kept(dataset: Path, tmp_path: Path) -> None:
    out = tmp_path / "run"
    train(dataset, out, tiny("mlp", steps=4, checkpoint_every=2))
    last = checkpoints(out)[-1]
    last.write_bytes(last.read_bytes()[:100])
    with pytest.raises(CheckpointError, match=rf"{last.name}.*delete it to resume from the one before"):
        train(dataset, out, tiny("mlp", steps=8, checkpoint_every=2), resume=True)
    assert len(last.read_bytes()) == 100 and len(checkpoints(out)) == 2


class FakeEnv(gym.Env):
    """An environment with the synthetic dataset's observations (or altered ones)."""

    def __init__(self, sizes: dict[str, int], fps: int = FPS, action: int = 8) -> None:
        self.observation_space = spaces.Dict({k: spaces.Box(-10, 10, shape=(n,)) for k, n in sizes.items()})
        self.action_space = spaces.Box(-10, 10, shape=(action,))
        self.metadata = {"render_fps": fps}


SIZES = {STATE: 8, EE: 7, ENV: 7}


@pytest.mark.parametrize("env, message", [
    (FakeEnv({STATE: 8, EE: 7}), f"no observation '{ENV}'"),
    (FakeEnv({**SIZES, ENV: 14}), rf"'{ENV}' is \(14,\) in the environment, \(7,\) in the checkpoint"),
    (FakeEnv(SIZES, fps=10), "steps at 10 Hz.*recorded at 20 fps"),
    (FakeEnv(SIZES, action=7), "the action is"),
])
def test_a_checkpoint_refuses_an_environment_that_differs(trained: Path, env: gym.Env, message: str) -> None:
    payload = load_checkpoint(trained)
    check_compatible(payload, FakeEnv(SIZES))  # the environment it was trained for passes
    with pytest.raises(EnvironmentMismatchError, match=message):
        check_compatible(payload, env)


def test_element_names_must_match_too(trained: Path) -> None:
    env = FakeEnv(SIZES)
    from vcage.data import Feature

    names = [f"mug.{c}" for c in ("x", "y", "z", "qw", "qx", "qy", "qz")]
    env.features = {ENV: Feature("float32", (7,), names=names)}
    with pytest.raises(EnvironmentMismatchError, match="other objects or order"):
        check_compatible(load_checkpoint(trained), env)


def test_evaluation_needs_an_environment_configuration(tmp_path: Path) -> None:
    plain = write_dataset(tmp_path / "plain", 2, config={})
    checkpoint = train(plain, tmp_path / "run", tiny("mlp", steps=2, checkpoint_every=2)).checkpoint
    with pytest.raises(PolicyError, match="stores no vcage configuration.*--env"):
        evaluate(checkpoint, 1)
    with pytest.raises(PolicyError, match="at least 1"):
        evaluate(checkpoint, 0)


def test_the_mismatch_is_found_before_any_rollout(trained: Path) -> None:
    stepped: list[np.ndarray] = []

    class Wrong(FakeEnv):
        def step(self, action: np.ndarray) -> Any:
            stepped.append(action)
            raise AssertionError("must not be stepped")

    with pytest.raises(EnvironmentMismatchError):
        evaluate(trained, 1, make_env=lambda config, **kw: Wrong({STATE: 8}))
    assert stepped == []
