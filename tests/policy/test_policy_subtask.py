"""Subtask-conditioned (hierarchical) policies: trained on each frame's ``subtask_index``, a
classifier head names the subtask at inference, and the runner never goes back to an earlier one."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch
from typer.testing import CliRunner

from conftest import ACTION, EE, ENV, FPS, STATE, features, tiny, write_dataset
from vcage.cli import app
from vcage.data import DatasetWriter, Feature
from vcage.errors import ConfigError, DatasetError
from vcage.policy.checkpoint import export_for_evaluation, load_checkpoint
from vcage.policy.config import SUBTASK, TrainConfig
from vcage.policy.dataset import load_training_data
from vcage.policy.errors import MissingFeatureError
from vcage.policy.inference import PolicyRunner
from vcage.policy.models import make_policy
from vcage.policy.normalize import Normalizer
from vcage.policy.train import Run, train
from vcage.policy.windows import make_windows


def two_phase(rng: np.random.Generator, length: int) -> dict[str, np.ndarray]:
    """The arm goes from its start to a target and back (subtask 0), then to a second target and back
    (subtask 1): the arm's state at the boundary is its state at the start, and only the block's
    height (lifted in subtask 0) tells the two apart, as a placed mouse does in a real plan."""
    half = length // 2
    start, first, second = (rng.uniform(-1, 1, 7) for _ in range(3))
    phase = (1 - np.cos(2 * np.pi * np.linspace(0, 1, half + 1)[:-1]))[:, None] / 2
    q = np.concatenate([start + (first - start) * phase, start + (second - start) * phase])
    n = len(q)
    action = np.concatenate([q[1:], q[-1:]])
    subtask = (np.arange(n) >= half).astype(np.int64)
    block = np.column_stack([np.full(n, 0.3), np.full(n, -0.2), 0.7 + 0.1 * subtask, np.ones(n),
                             np.zeros((n, 3))])
    frames = {STATE: np.column_stack([q, np.full(n, 0.08)]),
              EE: np.column_stack([np.tanh(q[:, :3]), np.ones(n), np.zeros((n, 3))]),
              ENV: block, ACTION: np.column_stack([action, np.ones(n)])}
    out = {k: v.astype(np.float32) for k, v in frames.items()}
    out[SUBTASK] = subtask[:, None]
    return out


def write_plan_dataset(root: Path, episodes: int, *, seed: int = 0, decreasing: bool = False) -> Path:
    rng = np.random.default_rng(seed)
    with DatasetWriter(root, fps=FPS, features={**features(), SUBTASK: Feature("int64", (1,))},
                       config={"synthetic": seed}) as writer:
        for e in range(episodes):
            frames = two_phase(rng, int(rng.integers(24, 36)))
            if decreasing and e == 1:
                frames[SUBTASK] = frames[SUBTASK][::-1].copy()
            writer.add_episode(frames, task="lift the block, then reach")
    return root


@pytest.fixture(scope="module")
def plan_dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_plan_dataset(tmp_path_factory.mktemp("subtask") / "ds", 6)


def test_the_config_takes_only_a_boolean_and_keeps_subtask_index_out_of_the_observations() -> None:
    with pytest.raises(ConfigError, match="subtask_conditioned"):
        TrainConfig(subtask_conditioned="yes")  # type: ignore[arg-type]
    with pytest.raises(ConfigError, match="subtask_index"):
        TrainConfig(observation_keys=(STATE, SUBTASK))
    assert TrainConfig.from_dict(TrainConfig(subtask_conditioned=True).to_dict()).subtask_conditioned


def test_a_dataset_without_subtask_index_is_refused_with_the_backfill_command(dataset: Path) -> None:
    with pytest.raises(MissingFeatureError, match=f"vcage backfill {dataset}"):
        load_training_data(dataset, tiny("mlp", subtask_conditioned=True))


def test_a_decreasing_subtask_sequence_is_a_dataset_error(tmp_path: Path) -> None:
    root = write_plan_dataset(tmp_path / "ds", 3, decreasing=True)
    with pytest.raises(DatasetError, match="episode 1"):
        load_training_data(root, tiny("mlp", subtask_conditioned=True))


def test_the_training_data_carry_each_frames_subtask_and_their_count(plan_dataset: Path) -> None:
    data = load_training_data(plan_dataset, tiny("mlp", subtask_conditioned=True))
    assert data.subtasks == 2 and data.subtask is not None and len(data.subtask) == len(data.obs)
    starts = np.concatenate([[0], np.cumsum(data.lengths)[:-1]])
    ends = starts + np.array(data.lengths) - 1
    assert (data.subtask[starts] == 0).all() and (data.subtask[ends] == 1).all()
    plain = load_training_data(plan_dataset, tiny("mlp"))
    assert plain.subtask is None and plain.subtasks == 0


def test_a_window_is_labelled_with_the_subtask_of_its_current_frame(plan_dataset: Path) -> None:
    config = tiny("mlp", subtask_conditioned=True, n_obs_steps=3, horizon=16)
    data = load_training_data(plan_dataset, config)
    norms = {"obs": Normalizer.fit(data.obs, "min_max"), "action": Normalizer.fit(data.action, "min_max")}
    run = Run(data, config, norms, torch.device("cpu"))
    windows = make_windows(data.lengths, 3, 16)
    rows = torch.arange(len(windows))
    _, _, subtask = run.gather(rows, run.obs_index, run.action_index)
    assert subtask is not None
    assert torch.equal(subtask, torch.from_numpy(data.subtask[windows.obs[:, -1]]))
    # at a boundary the window's oldest frame is in the subtask before: the label is not the oldest's
    assert (data.subtask[windows.obs[:, 0]] != data.subtask[windows.obs[:, -1]]).any()


@pytest.mark.parametrize("policy", ["diffusion", "mlp"])
def test_the_action_model_reads_the_subtask(policy: str) -> None:
    torch.manual_seed(0)
    model = make_policy(tiny(policy, subtask_conditioned=True), 12, 8, subtasks=3)
    obs, action = torch.randn(5, 2, 12), torch.randn(5, 16, 8)
    draws = model.draws(action.shape, torch.Generator().manual_seed(1), torch.device("cpu"))
    first = model.loss_from(obs, action, *draws, subtask=torch.zeros(5, dtype=torch.long))
    second = model.loss_from(obs, action, *draws, subtask=torch.full((5,), 2, dtype=torch.long))
    assert not torch.isclose(first, second)
    noise = torch.randn(5, 16, 8)
    assert not torch.allclose(model.predict_from(obs, noise, torch.zeros(5, dtype=torch.long)),
                              model.predict_from(obs, noise, torch.ones(5, dtype=torch.long)))
    with pytest.raises(ValueError, match="subtask of every sample"):
        model.loss_from(obs, action, *draws)
    plain = make_policy(tiny(policy), 12, 8)
    with pytest.raises(ValueError, match="not conditioned"):
        plain.classify(obs)


def test_training_teaches_the_classifier_the_subtasks_and_the_policy_to_use_them(plan_dataset: Path,
                                                                                 tmp_path: Path) -> None:
    config = tiny("mlp", subtask_conditioned=True, steps=400, checkpoint_every=400)
    summary = train(plan_dataset, tmp_path / "run", config)
    payload = load_checkpoint(summary.checkpoint)
    assert payload["subtasks"] == 2
    runner = PolicyRunner(payload)
    data = load_training_data(plan_dataset, config)
    windows = make_windows(data.lengths, 2, 16)
    obs = torch.from_numpy(runner.obs_norm.normalize(data.obs)[windows.obs])
    action = torch.from_numpy(runner.action_norm.normalize(data.action)[windows.action])
    truth = torch.from_numpy(data.subtask[windows.obs[:, -1]])
    with torch.no_grad():
        named = runner.model.classify(obs).argmax(dim=1)
        assert (named == truth).float().mean() > 0.95
        right = torch.nn.functional.mse_loss(runner.model.predict_from(obs, action, truth), action)
        wrong = torch.nn.functional.mse_loss(runner.model.predict_from(obs, action, 1 - truth), action)
    # the actions depend on the one-hot as well as on the block's height (1.25x in this deterministic run)
    assert wrong > 1.1 * right


def test_the_runner_moves_on_to_later_subtasks_and_never_back(plan_dataset: Path, tmp_path: Path) -> None:
    config = tiny("mlp", subtask_conditioned=True, steps=10, checkpoint_every=10)
    exported = export_for_evaluation(train(plan_dataset, tmp_path / "run", config).checkpoint,
                                     tmp_path / "policy.pt")
    runner = PolicyRunner(load_checkpoint(exported))
    last = runner.model.subtask_head[-1]  # type: ignore[index]
    obs = {STATE: np.zeros(8, np.float32), EE: np.r_[0, 0, 0, 1, 0, 0, 0].astype(np.float32),
           ENV: np.r_[0.3, -0.2, 0.7, 1, 0, 0, 0].astype(np.float32)}

    def named(k: int) -> None:  # the classifier now names subtask k whatever it sees
        with torch.no_grad():
            last.weight.zero_()
            last.bias.copy_(torch.tensor([5.0, -5.0] if k == 0 else [-5.0, 5.0]))

    named(1)
    runner.act(obs)
    assert runner.subtask == 1
    named(0)
    for _ in range(config.n_action_steps + 1):  # past the next chunk, which asks the classifier again
        runner.act(obs)
    assert runner.subtask == 1
    runner.reset()
    assert runner.subtask == 0
    runner.act(obs)
    assert runner.subtask == 0


def test_a_checkpoint_without_a_subtask_count_is_an_unconditioned_policy(dataset: Path,
                                                                         tmp_path: Path) -> None:
    payload = load_checkpoint(train(dataset, tmp_path / "run", tiny("mlp", steps=5, checkpoint_every=5))
                              .checkpoint)
    assert payload["subtasks"] == 0
    del payload["subtasks"]  # as checkpoints written before subtask conditioning
    runner = PolicyRunner(payload)
    assert runner.model.subtasks == 0 and runner.model.subtask_head is None


def test_the_cli_refuses_subtask_conditioning_on_a_dataset_without_subtasks(tmp_path: Path) -> None:
    root = write_dataset(tmp_path / "ds", 3)
    result = CliRunner().invoke(app, ["train", str(root), "--out", str(tmp_path / "run"), "--policy", "mlp",
                                      "--steps", "2", "--subtask-conditioned"])
    assert result.exit_code != 0
    assert "subtask_index" in result.output and "vcage backfill" in result.output
    assert not (tmp_path / "run" / "checkpoints").exists()


def test_evaluation_refuses_a_plan_with_another_number_of_subtasks(plan_dataset: Path, generated: Path,
                                                                    tmp_path: Path) -> None:
    from vcage.data.reader import DatasetReader
    from vcage.pipeline.evaluation import make_env
    from vcage.policy.errors import EnvironmentMismatchError
    from vcage.policy.evaluate import check_compatible

    config = tiny("mlp", subtask_conditioned=True, steps=2, checkpoint_every=2)
    payload = load_checkpoint(train(plan_dataset, tmp_path / "run", config).checkpoint)
    env = make_env(DatasetReader(generated).config, seed=0, max_steps=2)  # "press the bell": one subtask
    with pytest.raises(EnvironmentMismatchError, match="on 2 subtasks, the environment's plan has 1"):
        check_compatible(payload, env)
    payload["subtasks"] = 0
    with pytest.raises(EnvironmentMismatchError) as caught:
        check_compatible(payload, env)
    assert "subtasks" not in str(caught.value)
