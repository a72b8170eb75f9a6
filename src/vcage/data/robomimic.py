"""Export a dataset to robomimic's HDF5 layout, for policy-learning code that reads it.

One group per episode, ``data/demo_<k>``, with ``actions`` (T, A), ``obs/<key>`` per feature and
camera (images as (T, H, W, 3) uint8, gzip-compressed), ``states`` (the simulator states, for
replay in vcage), ``rewards`` (1 on the last frame of an episode the oracle confirmed, else 0) and
``dones`` (1 on the last frame); ``num_samples`` and the episode's seed and task as attributes.
``mask/train`` and ``mask/valid`` split the demos with a seeded permutation. ``next_obs`` is not
written (it would double the file); train with robomimic's ``hdf5_load_next_obs=False``.

The file is written next to its destination and renamed into place, so an interrupted export
leaves no partial file, and an existing file is only replaced when asked. A damaged dataset is
refused (CorruptDatasetError naming the files) by the cheap checks before anything is written,
and by the reads themselves for damage those checks cannot see.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

from vcage.data.reader import DatasetReader
from vcage.data.verify import check
from vcage.errors import CorruptDatasetError, DatasetError


@dataclass(frozen=True)
class ExportSummary:
    path: Path
    demos: int
    frames: int
    train: int
    valid: int
    obs_keys: tuple[str, ...]


def obs_key(feature: str) -> str:
    """``observation.state`` -> ``state``, ``observation.images.front`` -> ``front_image``."""
    parts = feature.split(".")
    if parts[:2] == ["observation", "images"]:
        return "_".join(parts[2:]) + "_image"
    return "_".join(parts[1:] if parts[0] == "observation" else parts)


def export_robomimic(dataset: str | Path, out: str | Path, *, valid_fraction: float = 0.1, seed: int = 0,
                     overwrite: bool = False) -> ExportSummary:
    """Write the dataset at ``dataset`` as a robomimic HDF5 file at ``out``.

    CorruptDatasetError if the dataset's files are damaged (run ``vcage verify --repair``).
    """
    out = Path(out)
    if not 0.0 <= valid_fraction < 1.0:
        raise DatasetError(f"valid_fraction must be in [0, 1), got {valid_fraction}")
    check(dataset).raise_if_damaged()
    reader = DatasetReader(dataset)
    if reader.num_episodes == 0:
        raise DatasetError(f"{reader.root} has no episodes to export")
    if out.exists() and not overwrite:
        raise DatasetError(f"{out} exists; pass overwrite=True (--overwrite) to replace it")
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(f".{out.name}.{os.getpid()}.tmp")
    features = [name for name in reader.features if name.startswith("observation.")]
    keys = tuple(obs_key(f) for f in features) + tuple(obs_key(c) for c in reader.cameras)
    names = [f"demo_{k}" for k in range(reader.num_episodes)]
    order = np.random.default_rng(seed).permutation(reader.num_episodes)
    n_valid = int(round(valid_fraction * reader.num_episodes))
    valid = sorted(order[:n_valid].tolist())
    frames = 0
    try:
        with h5py.File(tmp, "w") as f:
            data = f.create_group("data")
            for k, name in enumerate(names):
                try:
                    frames += _write_demo(data.create_group(name), reader, k, features)
                except CorruptDatasetError as exc:
                    raise CorruptDatasetError(f"episode {k} of {reader.root} is damaged: {exc}; run `vcage "
                                              f"verify {reader.root} --repair` to drop it") from exc
            data.attrs["total"] = frames
            data.attrs["env_args"] = json.dumps({
                "env_name": reader.tasks[0] if reader.tasks else "",
                "env_version": "vcage", "env_kwargs": {"dataset": str(reader.root.resolve()),
                                                       "config": reader.config}})
            mask = f.create_group("mask")
            train = [name for k, name in enumerate(names) if k not in valid]
            mask.create_dataset("train", data=np.array(train, dtype="S"))
            mask.create_dataset("valid", data=np.array([names[k] for k in valid], dtype="S"))
        os.replace(tmp, out)
    finally:
        tmp.unlink(missing_ok=True)
    return ExportSummary(out, len(names), frames, len(names) - len(valid), len(valid), keys)


def _write_demo(group: h5py.Group, reader: DatasetReader, k: int, features: list[str]) -> int:
    ep = reader.episode(k)
    n = ep.length
    group.attrs["num_samples"] = n
    group.attrs["vcage_episode"] = k
    group.attrs["seed"] = int(ep.extras.get("seed", -1))
    group.attrs["task"] = ep.task
    if "action" not in ep.frames:
        raise DatasetError(f"episode {k} of {reader.root} has no 'action' column; nothing to learn from")
    group.create_dataset("actions", data=ep.frames["action"].astype(np.float32))
    obs = group.create_group("obs")
    for name in features:
        obs.create_dataset(obs_key(name), data=ep.frames[name])
    for camera in reader.cameras:
        video = reader.video(k, camera)
        obs.create_dataset(obs_key(camera), data=video, chunks=(1, *video.shape[1:]), compression="gzip",
                           compression_opts=4)
    if "states" in ep.arrays:
        group.create_dataset("states", data=ep.arrays["states"])
    done = np.zeros(n, np.uint8)
    done[-1] = 1
    reward = done.astype(np.float32) * float(bool(ep.extras.get("oracle_success", False)))
    group.create_dataset("dones", data=done)
    group.create_dataset("rewards", data=reward)
    return n
