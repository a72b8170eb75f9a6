"""The frames a policy trains on, read from a LeRobot v3 dataset through :class:`DatasetReader`
(no torch): the chosen observation features side by side, the actions, the episode lengths, and
the dataset's fingerprint.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from vcage.data.reader import DatasetReader
from vcage.errors import DatasetError
from vcage.policy.config import DEFAULT_OBSERVATIONS, REQUIRED_OBSERVATIONS, SUBTASK, TrainConfig, split_key
from vcage.policy.encoding import VectorEncoder
from vcage.policy.errors import MissingFeatureError

MIN_EPISODES = 2


@dataclass(frozen=True)
class FeatureSpec:
    """A vector feature as a policy uses it: name (the observation key), size and element names (if
    the dataset has them). A key that selects elements (``observation.state[gripper_width]``) reads
    feature ``source`` and keeps the values at ``indices``."""

    name: str
    size: int
    names: tuple[str, ...] | None = None
    source: str | None = None  # the dataset's (and environment's) feature, when it differs from name
    indices: tuple[int, ...] | None = None  # the elements kept, in the source feature; None: all

    @property
    def feature(self) -> str:
        return self.source or self.name

    def select(self, values: np.ndarray) -> np.ndarray:
        """(..., source size) values of the source feature -> (..., size) the policy observes."""
        return values if self.indices is None else values[..., list(self.indices)]

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"name": self.name, "size": self.size,
                               "names": list(self.names) if self.names else None}
        if self.indices is not None:
            out.update(source=self.source, indices=list(self.indices))
        return out

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> FeatureSpec:
        names, indices = data.get("names"), data.get("indices")
        return cls(str(data["name"]), int(data["size"]), tuple(names) if names else None,
                   data.get("source"), tuple(int(i) for i in indices) if indices is not None else None)


@dataclass(frozen=True)
class DatasetInfo:
    """What a checkpoint records of the dataset it was trained on."""

    path: str
    fingerprint: str
    fps: int
    episodes: int
    frames: int
    config: dict[str, Any] | None  # meta/vcage.json's configuration: how to make its environment

    def to_dict(self) -> dict[str, Any]:
        return {"path": self.path, "fingerprint": self.fingerprint, "fps": self.fps,
                "episodes": self.episodes, "frames": self.frames, "config": self.config}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> DatasetInfo:
        return cls(str(data["path"]), str(data["fingerprint"]), int(data["fps"]), int(data["episodes"]),
                   int(data["frames"]), data.get("config"))


@dataclass(frozen=True, eq=False)
class TrainingData:
    """All frames of a dataset: ``obs`` (N, obs_dim) float32 (the features of ``obs_features``
    side by side, as :class:`VectorEncoder` gives them to the policy), ``action``
    (N, action_dim) float32 (the feature ``action_feature`` encoded the same way), ``lengths`` of
    the episodes in order; for a subtask-conditioned policy, ``subtask`` (N,) int64, the plan's
    subtask of each frame, of which there are ``subtasks``."""

    obs: np.ndarray
    action: np.ndarray
    lengths: tuple[int, ...]
    obs_features: tuple[FeatureSpec, ...]
    action_feature: FeatureSpec
    info: DatasetInfo
    notes: tuple[str, ...] = field(default=())  # things the user should know (e.g. a feature left out)
    subtask: np.ndarray | None = None
    subtasks: int = 0


def fingerprint(reader: DatasetReader) -> str:
    """A hash of what makes a dataset's content: its features, episode and frame counts, fps, and the
    configuration it was generated with."""
    content = {"features": reader.info.get("features"), "episodes": reader.num_episodes,
               "frames": reader.total_frames, "fps": reader.fps, "config": reader.config}
    return hashlib.sha256(json.dumps(content, sort_keys=True, default=str).encode()).hexdigest()[:16]


def observation_keys(reader: DatasetReader,
                     keys: tuple[str, ...] | None) -> tuple[tuple[str, ...], list[str]]:
    """The observation features to use and notes: ``keys``, or the defaults the dataset has."""
    root = reader.root
    wanted = keys if keys is not None else REQUIRED_OBSERVATIONS
    for key in wanted:
        if split_key(key)[0] not in reader.features:
            raise MissingFeatureError(
                f"the dataset {root} has no feature {split_key(key)[0]!r} (it has "
                f"{', '.join(sorted(reader.features))}); "
                f"run `vcage backfill {root}` to add the features policies train on"
                + ("" if keys is None else ", or choose other observation features"))
    if keys is not None:
        return keys, []
    chosen = tuple(k for k in DEFAULT_OBSERVATIONS if k in reader.features)
    notes = [f"the dataset has no {k!r}: the policy does not observe it (run `vcage backfill {root}` to "
             "add it)" for k in DEFAULT_OBSERVATIONS if k not in reader.features]
    return chosen, notes


def load_training_data(root: str | Path, config: TrainConfig) -> TrainingData:
    """Read every episode of the dataset at ``root`` with the features ``config`` asks for.

    Raises:
        DatasetError: not a dataset, fewer than two episodes, or non-finite values.
        MissingFeatureError: a needed feature is absent (the message names the back-fill command).
    """
    reader = DatasetReader(root, videos=False)  # the tables alone: a copy without videos/ trains the same
    if reader.num_episodes < MIN_EPISODES:
        raise DatasetError(f"the dataset {reader.root} has {reader.num_episodes} episode(s); training needs "
                           f"at least {MIN_EPISODES} (`vcage generate ... --out {reader.root} --episodes N "
                           "--total` adds more)")
    if config.action_key not in reader.features:
        raise MissingFeatureError(
            f"the dataset {reader.root} has no feature {config.action_key!r} to train on (it has "
            f"{', '.join(sorted(reader.features))}); run `vcage backfill {reader.root}` to add it")
    if config.subtask_conditioned and SUBTASK not in reader.features:
        raise MissingFeatureError(
            f"a subtask-conditioned policy learns from each frame's {SUBTASK!r}, which the dataset "
            f"{reader.root} lacks; run `vcage backfill {reader.root}` to add it (a dataset of a plan), or "
            "train without --subtask-conditioned")
    keys, notes = observation_keys(reader, config.observation_keys)
    specs = tuple(_spec(reader, k) for k in keys)
    obs_parts: list[list[np.ndarray]] = [[] for _ in keys]
    actions, lengths, subtask = [], [], []
    for i in range(reader.num_episodes):
        frames = reader.episode(i).frames
        for part, spec in zip(obs_parts, specs, strict=True):
            part.append(spec.select(_vectors(frames[spec.feature], spec.feature, i, reader.root)))
        actions.append(_vectors(frames[config.action_key], config.action_key, i, reader.root))
        lengths.append(len(actions[-1]))
        if config.subtask_conditioned:
            subtask.append(_subtasks(frames[SUBTASK], i, reader.root))
    raw = np.concatenate([np.concatenate(p) for p in obs_parts], axis=1)
    obs = VectorEncoder(specs, config.rotations, config.relative_objects)(raw)
    action_spec = _spec(reader, config.action_key)
    action = VectorEncoder([action_spec], config.rotations)(np.concatenate(actions))
    info = DatasetInfo(str(reader.root), fingerprint(reader), reader.fps, reader.num_episodes,
                       reader.total_frames, reader.config)
    labels = np.concatenate(subtask) if subtask else None
    count = int(labels.max()) + 1 if labels is not None else 0
    if labels is not None and count < 2:
        notes.append(f"every frame of {reader.root} belongs to subtask 0: conditioning on the subtask tells "
                     "the policy nothing")
    return TrainingData(obs, action, tuple(lengths), specs, action_spec, info, tuple(notes), labels, count)


def _spec(reader: DatasetReader, key: str) -> FeatureSpec:
    source, elements = split_key(key)
    feature = reader.features[source]
    names = tuple(feature.names) if feature.names else None
    if elements is None:
        return FeatureSpec(key, int(feature.shape[0]), names)
    missing = [e for e in elements if not names or e not in names]
    if missing:
        raise MissingFeatureError(f"the dataset {reader.root}'s feature {source!r} has no element(s) "
                                  f"{', '.join(missing)} (it has {', '.join(names or ('no names',))})")
    assert names is not None
    return FeatureSpec(key, len(elements), elements, source, tuple(names.index(e) for e in elements))


def _subtasks(values: np.ndarray, episode: int, root: Path) -> np.ndarray:
    """An episode's per-frame subtask indices, checked: whole numbers from 0, never decreasing."""
    x = np.asarray(values).reshape(-1)
    if len(x) and (not np.all(np.isfinite(x)) or np.any(x < 0) or np.any(x != np.round(x))
                   or np.any(np.diff(x) < 0)):
        raise DatasetError(f"{root}: {SUBTASK!r} of episode {episode} is not a non-decreasing sequence of "
                           "subtask numbers from 0; `vcage backfill` the dataset again")
    return x.astype(np.int64)


def _vectors(values: np.ndarray, key: str, episode: int, root: Path) -> np.ndarray:
    x = np.asarray(values, dtype=np.float32)
    x = x.reshape(len(x), -1)
    if not np.isfinite(x).all():
        raise DatasetError(f"{root}: feature {key!r} of episode {episode} holds NaN or infinite values; "
                           "`vcage verify` the dataset, or drop the episode")
    return x
