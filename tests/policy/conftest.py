"""Small synthetic datasets written with ``DatasetWriter``, and tiny policy configurations.

Every test here runs torch on one thread, so results are reproducible and the tests share the
machine's cores with the rest of the suite.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
import torch

from vcage.data import DatasetWriter, Feature
from vcage.policy.config import DiffusionConfig, MlpConfig, TrainConfig

STATE, EE, ENV, ACTION = "observation.state", "observation.ee_pose", "observation.environment_state", "action"
FPS = 20


@pytest.fixture(autouse=True)
def one_thread() -> Iterator[None]:
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(threads)


def features(with_env: bool = True) -> dict[str, Feature]:
    out = {STATE: Feature("float32", (8,), names=[*(f"joint{i}" for i in range(1, 8)), "gripper_width"]),
           EE: Feature("float32", (7,), names=["x", "y", "z", "qw", "qx", "qy", "qz"])}
    if with_env:
        out[ENV] = Feature("float32", (7,), names=["block.x", "block.y", "block.z", "block.qw", "block.qx",
                                                   "block.qy", "block.qz"])
    out[ACTION] = Feature("float32", (8,), names=[*(f"joint{i}" for i in range(1, 8)), "gripper"])
    return out


def episode(rng: np.random.Generator, length: int, with_env: bool = True) -> dict[str, np.ndarray]:
    """Joints swing towards an object-dependent target; the action is the next frame's joints and a
    gripper that closes half-way: a deterministic function of the observations."""
    target = rng.uniform(-1, 1, 7)
    start = rng.uniform(-1, 1, 7)
    phase = np.linspace(0, 1, length + 1)[:, None]
    q = start + (target - start) * (1 - np.cos(np.pi * phase)) / 2
    grip = (np.arange(length + 1) < length // 2).astype(np.float32)
    state = np.column_stack([q[:-1], 0.08 * grip[:-1]])
    ee = np.column_stack([np.tanh(q[:-1, :3]), np.ones(length), np.zeros((length, 3))])
    frames = {STATE: state, EE: ee, ACTION: np.column_stack([q[1:], grip[1:]])}
    if with_env:
        frames[ENV] = np.tile(np.r_[target[:3], 1.0, 0, 0, 0], (length, 1))
    return {k: v.astype(np.float32) for k, v in frames.items()}


def write_dataset(root: Path, episodes: int, *, with_env: bool = True, seed: int = 0,
                  config: dict | None = None, drop: tuple[str, ...] = ()) -> Path:
    """``episodes`` synthetic episodes (without the features in ``drop``) at ``root``."""
    rng = np.random.default_rng(seed)
    kept = {k: f for k, f in features(with_env).items() if k not in drop}
    with DatasetWriter(root, fps=FPS, features=kept,
                       config=config if config is not None else {"synthetic": seed}) as writer:
        for _ in range(episodes):
            frames = episode(rng, int(rng.integers(24, 40)), with_env)
            writer.add_episode({k: v for k, v in frames.items() if k in kept}, task="reach the block")
    return root


@pytest.fixture(scope="session")
def dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Six episodes with state, end-effector pose and environment state."""
    return write_dataset(tmp_path_factory.mktemp("policy") / "ds", 6)


def tiny(policy: str, **changes: object) -> TrainConfig:
    """A configuration small enough for a test: a few thousand parameters, small batches."""
    base: dict[str, object] = {"policy": policy, "steps": 30, "batch_size": 16, "lr": 3e-3, "warmup_steps": 5,
                               "checkpoint_every": 10,
                               "diffusion": DiffusionConfig(down_dims=(16, 32), n_groups=4, step_embed_dim=16,
                                                            inference_steps=5),
                               "mlp": MlpConfig(hidden=(64, 64))}
    base.update(changes)
    return TrainConfig(**base)  # type: ignore[arg-type]


@pytest.fixture(scope="session")
def generated(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Two real episodes of "press the bell" (oracle critic, no clutter, one small camera)."""
    from typer.testing import CliRunner

    from vcage.cli import app

    out = tmp_path_factory.mktemp("generated") / "bell"
    result = CliRunner().invoke(app, ["generate", "press the bell", "--episodes", "2", "--critic", "oracle",
                                      "--clutter", "0", "--size", "64", "--cameras", "front",
                                      "--out", str(out)])
    assert result.exit_code == 0, result.output
    return out


SIMULATOR_AND_CODEC = ("mujoco", "mink", "daqp", "av", "shapely", "trimesh")


def blocked_modules(folder: Path, names: tuple[str, ...] = SIMULATOR_AND_CODEC) -> Path:
    """A folder that, first on PYTHONPATH, makes importing each of ``names`` fail as if it were not
    installed (what a machine that only trains has)."""
    for name in names:
        (folder / name).mkdir(parents=True, exist_ok=True)
        (folder / name / "__init__.py").write_text(f"raise ImportError('{name} is not installed here')\n")
    return folder
