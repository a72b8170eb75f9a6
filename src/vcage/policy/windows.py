"""Training windows over episodes, as LeRobot's ``delta_timestamps`` make them (no torch).

A sample is anchored at one frame ``t`` of one episode. Its observation window holds the frames
``t - n_obs + 1 .. t`` and its action chunk the frames ``t - n_obs + 1 .. t - n_obs + horizon``
(Diffusion Policy's convention: the chunk starts with the oldest observed frame, and the actions
executed at inference start at the current frame, index ``n_obs - 1`` of the chunk). With a
``stride`` above 1 the window holds every ``stride``-th frame back from ``t`` instead
(``t - (n_obs - 1) * stride, ..., t - stride, t``) and the action chunk stays where it was. Indices
before an episode's first frame repeat the first frame, indices past its last frame repeat the last
one, so a window never mixes episodes.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Windows:
    """Global frame indices of every sample: ``obs`` (N, n_obs) and ``action`` (N, horizon), into
    the frames of all episodes concatenated in order; ``episode`` (N,) the episode of each sample."""

    obs: np.ndarray
    action: np.ndarray
    episode: np.ndarray

    def __len__(self) -> int:
        return len(self.obs)


def episode_offsets(lengths: Sequence[int]) -> np.ndarray:
    """Index of each episode's first frame in the concatenated frames."""
    return np.concatenate([[0], np.cumsum(lengths)[:-1]]).astype(np.int64) if len(lengths) else \
        np.zeros(0, dtype=np.int64)


def make_windows(lengths: Sequence[int], n_obs: int, horizon: int, stride: int = 1) -> Windows:
    """The windows anchored at every frame of every episode (episodes of ``lengths`` frames each),
    observing every ``stride``-th frame."""
    obs, action, episode = [], [], []
    first_offset = -(n_obs - 1)
    observed = np.arange(-(n_obs - 1) * stride, 1, stride)
    for e, (start, length) in enumerate(zip(episode_offsets(lengths), lengths, strict=True)):
        if length < 1:
            continue
        t = np.arange(length)[:, None]
        obs.append(start + np.clip(t + observed, 0, length - 1))
        action.append(start + np.clip(t + np.arange(first_offset, first_offset + horizon), 0, length - 1))
        episode.append(np.full(length, e))
    if not obs:
        empty = np.zeros((0, n_obs), dtype=np.int64)
        return Windows(empty, np.zeros((0, horizon), dtype=np.int64), np.zeros(0, dtype=np.int64))
    return Windows(np.concatenate(obs).astype(np.int64), np.concatenate(action).astype(np.int64),
                   np.concatenate(episode).astype(np.int64))
