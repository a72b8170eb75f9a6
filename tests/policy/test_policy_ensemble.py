"""Temporal ensembling: which chunks a runner predicts, and the weighted mean it acts on."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import torch

from conftest import features, tiny
from vcage.policy.checkpoint import load_checkpoint
from vcage.policy.ensemble import ChunkBlend, TemporalEnsemble
from vcage.policy.errors import PolicyError
from vcage.policy.inference import PolicyRunner
from vcage.policy.train import train


def chunk(start: float, length: int = 4) -> np.ndarray:
    """Actions start, start + 1, ... (two values each, the second the negative of the first)."""
    values = start + np.arange(length, dtype=float)
    return np.column_stack([values, -values])


def test_one_chunk_is_replayed_in_order() -> None:
    blend = ChunkBlend(TemporalEnsemble(every=4, decay=0.5), chunk_length=4)
    assert blend.due()
    blend.add(chunk(10))
    acted = []
    for _ in range(4):
        acted.append(blend.next())
    np.testing.assert_allclose(np.stack(acted), chunk(10))
    assert blend.due()  # step 4: the next chunk is due


def test_overlapping_chunks_are_averaged_with_the_oldest_weighted_most() -> None:
    decay = 0.7
    blend = ChunkBlend(TemporalEnsemble(every=1, decay=decay), chunk_length=4)
    blend.add(chunk(0))  # step 0
    np.testing.assert_allclose(blend.next(), [0, 0])
    blend.add(chunk(100))  # step 1: chunk(0) says 1, this one 100
    w = np.exp(-decay)
    np.testing.assert_allclose(blend.next(), np.array([1 + w * 100, -(1 + w * 100)]) / (1 + w))
    blend.add(chunk(200))  # step 2: 2, 101 and 200, weights 1, w, w^2
    expected = (2 + w * 101 + w * w * 200) / (1 + w + w * w)
    np.testing.assert_allclose(blend.next(), [expected, -expected])


def test_a_decay_of_zero_is_the_plain_mean_and_expired_chunks_drop_out() -> None:
    blend = ChunkBlend(TemporalEnsemble(every=2, decay=0.0), chunk_length=3)
    blend.add(chunk(0, 3))
    blend.next()
    blend.next()
    blend.add(chunk(50, 3))  # step 2: chunk(0) still says 2
    np.testing.assert_allclose(blend.next(), [26, -26])
    np.testing.assert_allclose(blend.next(), [51, -51])  # step 3: chunk(0) has run out
    blend.add(chunk(80, 3))
    np.testing.assert_allclose(blend.next(), [(52 + 80) / 2, -(52 + 80) / 2])


def test_acting_with_no_chunk_covering_the_step_is_an_error() -> None:
    blend = ChunkBlend(TemporalEnsemble(every=2), chunk_length=2)
    with pytest.raises(PolicyError, match="predict one before acting"):
        blend.next()
    blend.add(chunk(0, 2))
    blend.next()
    blend.next()
    with pytest.raises(PolicyError, match="predict one before acting"):
        blend.next()


@pytest.mark.parametrize("every, decay, match", [(0, 0.01, "every N >= 1"), (True, 0.01, "every N >= 1"),
                                                 (1.5, 0.01, "every N >= 1"), (1, -0.1, "decay"),
                                                 (1, float("nan"), "decay")])
def test_an_ensemble_out_of_range_is_refused(every: Any, decay: Any, match: str) -> None:
    with pytest.raises(PolicyError, match=match):
        TemporalEnsemble(every=every, decay=decay)


def test_an_ensemble_period_longer_than_a_chunk_is_refused() -> None:
    with pytest.raises(PolicyError, match="choose every <= 4"):
        ChunkBlend(TemporalEnsemble(every=5), chunk_length=4)


@pytest.fixture(scope="module")
def mlp_checkpoint(dataset: Path, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    run = train(dataset, tmp_path_factory.mktemp("ensemble"), tiny("mlp", steps=2, checkpoint_every=2))
    return load_checkpoint(run.checkpoint)


def observation(k: int) -> dict[str, np.ndarray]:
    """A different observation at every step, so that every chunk differs."""
    return {name: np.full(feature.shape, 0.05 * k, dtype=np.float32)
            for name, feature in features().items() if not name.startswith("action")}


def record_chunks(runner: PolicyRunner) -> list[np.ndarray]:
    """The chunks the runner's model predicts from now on, unnormalised, from the current frame on."""
    chunks: list[np.ndarray] = []
    predict = runner.model.predict_from

    def recording(windows: torch.Tensor, noise: torch.Tensor, subtask: Any) -> torch.Tensor:
        out = predict(windows, noise, subtask)
        start = runner.config.n_obs_steps - 1
        chunks.extend(runner.action_norm.unnormalize(c[start:]) for c in out.numpy())
        return out

    runner.model.predict_from = recording  # type: ignore[method-assign]
    return chunks


@pytest.mark.parametrize("every, expected_chunks", [(1, 10), (4, 3), (12, 1)])
def test_a_runner_predicts_a_chunk_every_n_steps(mlp_checkpoint: dict[str, Any], every: int,
                                                  expected_chunks: int) -> None:
    runner = PolicyRunner(mlp_checkpoint, ensemble=TemporalEnsemble(every=every))
    chunks = record_chunks(runner)
    for k in range(10):
        runner.act(observation(k))
    assert len(chunks) == expected_chunks
    plain = PolicyRunner(mlp_checkpoint)  # n_action_steps (8) of each chunk
    plain_chunks = record_chunks(plain)
    for k in range(10):
        plain.act(observation(k))
    assert len(plain_chunks) == 2


def test_a_runner_acts_on_the_weighted_mean_of_its_chunks(mlp_checkpoint: dict[str, Any]) -> None:
    decay = 0.3
    runner = PolicyRunner(mlp_checkpoint, ensemble=TemporalEnsemble(every=1, decay=decay))
    chunks = record_chunks(runner)
    acted = [runner.act(observation(k)) for k in range(3)]
    assert not np.allclose(chunks[0][2], chunks[2][0], atol=1e-4)  # the chunks differ
    np.testing.assert_allclose(acted[0], chunks[0][0], rtol=1e-5, atol=1e-6)
    w = np.exp(-decay * np.arange(3))
    expected = (w[0] * chunks[0][2] + w[1] * chunks[1][1] + w[2] * chunks[2][0]) / w.sum()
    np.testing.assert_allclose(acted[2], expected, rtol=1e-5, atol=1e-6)
    runner.reset()  # a new episode forgets the chunks of the last one
    chunks.clear()
    first = runner.act(observation(7))
    np.testing.assert_allclose(first, chunks[0][0], rtol=1e-5, atol=1e-6)
