"""Training windows: the frames LeRobot's delta_timestamps would give, padded within each episode."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from conftest import ACTION, STATE, tiny
from vcage.policy.dataset import load_training_data
from vcage.policy.windows import make_windows


def test_windows_pad_by_repeating_the_first_and_last_frame_of_their_own_episode() -> None:
    w = make_windows([3, 5], n_obs=2, horizon=4)
    assert len(w) == 8 and w.episode.tolist() == [0, 0, 0, 1, 1, 1, 1, 1]
    # episode 0 holds frames 0..2: the first window repeats frame 0 for the previous observation
    assert w.obs[:3].tolist() == [[0, 0], [0, 1], [1, 2]]
    # actions start at the previous frame and repeat the last frame past the end
    assert w.action[:3].tolist() == [[0, 0, 1, 2], [0, 1, 2, 2], [1, 2, 2, 2]]
    # episode 1 holds frames 3..7 and never reaches back into episode 0
    assert w.obs[3].tolist() == [3, 3] and w.action[3].tolist() == [3, 3, 4, 5]
    assert w.action[-1].tolist() == [6, 7, 7, 7]


def test_a_strided_window_observes_every_kth_frame_back_and_keeps_the_action_chunk() -> None:
    w = make_windows([10], n_obs=3, horizon=4, stride=4)
    assert w.obs[9].tolist() == [1, 5, 9] and w.obs[5].tolist() == [0, 1, 5]  # clipped at the first frame
    assert w.obs[0].tolist() == [0, 0, 0]
    plain = make_windows([10], n_obs=3, horizon=4)
    # the chunk still starts n_obs - 1 frames back, so the executed actions start at the current frame
    assert np.array_equal(w.action, plain.action) and w.action[9].tolist() == [7, 8, 9, 9]


def test_every_window_stays_in_its_episode(dataset: Path) -> None:
    data = load_training_data(dataset, tiny("mlp"))
    w = make_windows(data.lengths, 2, 16)
    starts = np.concatenate([[0], np.cumsum(data.lengths)[:-1]])
    ends = starts + np.asarray(data.lengths) - 1
    lo, hi = starts[w.episode][:, None], ends[w.episode][:, None]
    assert ((w.obs >= lo) & (w.obs <= hi)).all() and ((w.action >= lo) & (w.action <= hi)).all()
    assert len(w) == sum(data.lengths)  # one window per frame


def test_the_loaded_frames_are_the_datasets_in_order(dataset: Path) -> None:
    from vcage.data import DatasetReader

    data = load_training_data(dataset, tiny("mlp", observation_keys=(STATE,)))
    reader = DatasetReader(dataset)
    first = reader.episode(0).frames
    assert data.obs.shape == (reader.total_frames, 8)
    np.testing.assert_array_equal(data.obs[:len(first[STATE])], first[STATE])
    last = reader.episode(reader.num_episodes - 1).frames[ACTION]
    np.testing.assert_array_equal(data.action[-3:], last[-3:])
    assert [f.name for f in data.obs_features] == [STATE]
