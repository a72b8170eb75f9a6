"""The LeRobot v3 layout (features, path templates) and a reader for datasets in it.

``meta/info.json`` is the commit point: rows and files beyond its ``total_episodes`` are ignored.
"""

from __future__ import annotations

import json
import zipfile
import zlib
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq

from vcage.data.layout import (
    ARRAYS_PATH,
    CODEBASE_VERSION,
    EXTRAS_PATH,
    INFO_PATH,
    TASKS_PATH,
    VCAGE_PATH,
)
from vcage.data.schema import schema_of
from vcage.data.video import decode_window
from vcage.errors import CorruptDatasetError, DatasetError

DTYPES = {"float32": pa.float32(), "float64": pa.float64(), "int32": pa.int32(), "int64": pa.int64(),
          "bool": pa.bool_()}
# Columns every LeRobot frame row has, besides the features.
STANDARD_COLUMNS = {"timestamp": "float32", "frame_index": "int64", "episode_index": "int64",
                    "index": "int64", "task_index": "int64"}


@dataclass(frozen=True)
class Feature:
    """A per-frame vector column: dtype (float32, float64, int32, int64, bool), shape (n,), optional names."""

    dtype: str
    shape: tuple[int, ...]
    names: Sequence[str] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "shape", tuple(int(s) for s in self.shape))
        if self.names is not None:
            object.__setattr__(self, "names", tuple(str(n) for n in self.names))
        if self.dtype not in DTYPES:
            raise DatasetError(f"feature dtype {self.dtype!r} is not supported; use one of "
                               f"{', '.join(DTYPES)}")
        if len(self.shape) != 1 or self.shape[0] < 1:
            raise DatasetError(f"feature shape {self.shape} is not supported; use a 1-D shape (n,), n >= 1")
        if self.names is not None and len(self.names) != self.shape[0]:
            raise DatasetError(f"feature has {len(self.names)} names for shape {self.shape}; "
                               "give one name per element")

    def to_info(self) -> dict[str, Any]:
        return {"dtype": self.dtype, "shape": list(self.shape),
                "names": list(self.names) if self.names is not None else None}

    @classmethod
    def from_info(cls, info: dict[str, Any]) -> Feature:
        names = info.get("names")
        if isinstance(names, dict):  # LeRobot also allows {"motors": [...]}
            lists = [v for v in names.values() if isinstance(v, list)]
            names = lists[0] if len(lists) == 1 else None
        return cls(str(info["dtype"]), tuple(info["shape"]), names)


@dataclass(frozen=True, eq=False)
class Episode:
    """One episode: frames holds every data column, (T, n) for features and (T,) for the standard ones."""

    index: int
    task: str
    length: int
    frames: dict[str, np.ndarray]
    extras: dict[str, Any]
    arrays: dict[str, np.ndarray]


def load_json(path: Path) -> Any:
    """Parse a JSON file; missing or invalid files raise DatasetError naming the file."""
    try:
        return json.loads(path.read_text())
    except FileNotFoundError:
        raise DatasetError(f"{path} is missing; the dataset is incomplete or this is not a dataset") from None
    except (OSError, ValueError) as exc:
        raise CorruptDatasetError(f"{path} is not readable JSON: {exc}") from exc


def read_parquet(path: Path) -> pa.Table:
    """Read a parquet file; missing or unreadable files raise DatasetError naming the file."""
    if not path.is_file():
        raise CorruptDatasetError(f"{path} is missing; the dataset is incomplete")
    try:
        return pq.read_table(path)
    except (OSError, ValueError, pa.ArrowException) as exc:
        raise CorruptDatasetError(f"{path} is not a readable parquet file: {exc}") from exc


# What reading a damaged npz raises: a truncated zip, a bad CRC, a broken deflate stream, a bad header.
NPZ_ERRORS = (zipfile.BadZipFile, zlib.error, EOFError, OSError, ValueError, KeyError)


def load_npz(path: Path) -> dict[str, np.ndarray]:
    """Every array of an ``.npz`` file; CorruptDatasetError naming the file if it cannot be read."""
    try:
        with np.load(path, allow_pickle=False) as npz:
            return {key: npz[key] for key in npz.files}
    except NPZ_ERRORS as exc:
        raise CorruptDatasetError(f"{path} is not a readable npz file: {exc}") from exc


def column_to_numpy(column: pa.ChunkedArray | pa.Array) -> np.ndarray:
    """A fixed-size list column as (T, n), a primitive column as (T,)."""
    array = column.combine_chunks() if isinstance(column, pa.ChunkedArray) else column
    if pa.types.is_fixed_size_list(array.type):
        values = array.flatten().to_numpy(zero_copy_only=False)
        return values.reshape(len(array), array.type.list_size)
    if pa.types.is_list(array.type) or pa.types.is_large_list(array.type):
        return np.asarray(array.to_pylist())
    return array.to_numpy(zero_copy_only=False)


class DatasetReader:
    """Reads a LeRobot v3 dataset (vcage-written or any with the same layout) and vcage extras.

    ``videos=False`` reads the tables alone: the videos need not be present (a copy of ``meta/`` and
    ``data/`` carried to a machine that trains a state-based policy), and asking for images fails.
    """

    def __init__(self, root: str | Path, *, videos: bool = True) -> None:
        self.root = Path(root)
        self.videos = videos
        if not self.root.is_dir():  # bad input, not a damaged dataset
            what = "a file" if self.root.exists() else "missing"
            raise DatasetError(f"{self.root} is {what}, not a dataset directory; give the directory a "
                               "dataset was written to")
        self.info: dict[str, Any] = load_json(self.root / INFO_PATH)
        try:
            self._parse_info()
        except (KeyError, TypeError, ValueError) as exc:
            raise CorruptDatasetError(f"{self.root / INFO_PATH} lacks or mangles a required key: "
                                      f"{exc}") from exc
        vcage = self.root / VCAGE_PATH
        self.config: dict[str, Any] | None = None
        if vcage.exists():
            marker = load_json(vcage)
            if not isinstance(marker, dict):
                raise CorruptDatasetError(f"{vcage} does not hold a JSON object; the dataset is corrupt")
            schema_of(marker, vcage)  # a newer vcage's dataset is refused, not misread
            self.config = marker.get("config")
        self._uncommitted = False  # meta rows beyond the commit point (left by a crash)
        self.tasks: list[str] = self._read_tasks() if self.num_episodes else []
        self._rows: list[dict[str, Any]] = self._read_episode_rows() if self.num_episodes else []
        self._check_files()

    def _parse_info(self) -> None:
        info = self.info
        if info["codebase_version"] != CODEBASE_VERSION:
            raise DatasetError(f"{self.root / INFO_PATH}: codebase_version {info['codebase_version']!r} "
                               f"is not {CODEBASE_VERSION!r}; only LeRobot v3 datasets are supported")
        self.fps = int(info["fps"])
        self.num_episodes = int(info["total_episodes"])
        self.total_frames = int(info["total_frames"])
        self.robot_type = info.get("robot_type")
        self.features: dict[str, Feature] = {}
        self.cameras: dict[str, tuple[int, int]] = {}
        for key, ft in info["features"].items():
            if ft["dtype"] == "video":
                self.cameras[key] = (int(ft["shape"][0]), int(ft["shape"][1]))
            elif key not in STANDARD_COLUMNS and ft["dtype"] in DTYPES and len(ft["shape"]) == 1:
                self.features[key] = Feature.from_info(ft)

    def _read_tasks(self) -> list[str]:
        path = self.root / TASKS_PATH
        table = read_parquet(path)
        if "task" not in table.column_names or "task_index" not in table.column_names:
            raise CorruptDatasetError(f"{path} needs columns 'task' and 'task_index', has "
                                      f"{table.column_names}")
        by_index = dict(zip(table.column("task_index").to_pylist(), table.column("task").to_pylist(),
                            strict=True))
        total = int(self.info.get("total_tasks", len(by_index)))
        self._uncommitted |= len(by_index) > total
        if sorted(by_index)[:total] != list(range(total)):
            raise CorruptDatasetError(f"{path} does not hold task indices 0..{total - 1} that {INFO_PATH} "
                                      "declares")
        return [by_index[i] for i in range(total)]

    def _read_episode_rows(self) -> list[dict[str, Any]]:
        files = sorted((self.root / "meta" / "episodes").glob("chunk-*/file-*.parquet"))
        rows: dict[int, dict[str, Any]] = {}
        for path in files:
            for row in read_parquet(path).to_pylist():
                if row["episode_index"] < self.num_episodes:
                    rows[int(row["episode_index"])] = row
                else:
                    self._uncommitted = True
        if len(rows) != self.num_episodes:
            where = ", ".join(str(p.relative_to(self.root)) for p in files) or "meta/episodes/ (no files)"
            raise CorruptDatasetError(f"episode count mismatch: {self.root / INFO_PATH} says "
                                      f"{self.num_episodes} episodes but {where} describe {len(rows)} of "
                                      "them; the dataset is corrupt")
        ordered = [rows[i] for i in range(self.num_episodes)]
        total = sum(int(r["length"]) for r in ordered)
        if total != self.total_frames:
            raise CorruptDatasetError(f"{self.root / INFO_PATH} says {self.total_frames} frames but the "
                                      f"episodes add up to {total}; the dataset is corrupt")
        return ordered

    def _check_files(self) -> None:
        for i in range(self.num_episodes):
            paths = [self.data_path(i)] + [self.video_path(i, key) for key in self.cameras if self.videos]
            for path in paths:
                if not path.is_file():
                    raise CorruptDatasetError(f"{path} (episode {i}) is missing; the dataset is corrupt")

    def __len__(self) -> int:
        return self.num_episodes

    def episode_meta(self, index: int) -> dict[str, Any]:
        """The row of ``meta/episodes`` for an episode (offsets, lengths, per-episode stats)."""
        if not 0 <= index < self.num_episodes:
            raise DatasetError(f"episode {index} does not exist; the dataset has {self.num_episodes} "
                               "episodes")
        return self._rows[index]

    def data_path(self, index: int) -> Path:
        row = self.episode_meta(index)
        return self.root / self.info["data_path"].format(
            chunk_index=row["data/chunk_index"], file_index=row["data/file_index"])

    def video_path(self, index: int, key: str) -> Path:
        if key not in self.cameras:
            raise DatasetError(f"unknown camera {key!r}; the dataset has {sorted(self.cameras)}")
        row = self.episode_meta(index)
        return self.root / self.info["video_path"].format(
            video_key=key, chunk_index=row[f"videos/{key}/chunk_index"],
            file_index=row[f"videos/{key}/file_index"])

    def episode(self, index: int) -> Episode:
        """Frames, task, extras and arrays of one episode (videos are read with :meth:`video`)."""
        row = self.episode_meta(index)
        path = self.data_path(index)
        table = read_parquet(path)
        if "episode_index" not in table.column_names:
            raise CorruptDatasetError(f"{path} has no 'episode_index' column; the dataset is corrupt")
        table = table.filter(pc.equal(table.column("episode_index"), index))
        if table.num_rows != row["length"]:
            raise CorruptDatasetError(f"{path} holds {table.num_rows} frames of episode {index}, "
                               f"meta/episodes says {row['length']}; the dataset is corrupt")
        frames = {name: column_to_numpy(table.column(name)) for name in table.column_names}
        for name, feature in self.features.items():
            if name in frames and frames[name].ndim == 1:
                frames[name] = frames[name].reshape(-1, *feature.shape)
        tasks = row.get("tasks") or []
        return Episode(index, str(tasks[0]) if tasks else "", int(row["length"]), frames,
                       self.extras(index), self.arrays(index))

    def extras(self, index: int) -> dict[str, Any]:
        path = self.root / EXTRAS_PATH.format(episode_index=index)
        if not path.exists():
            return {}
        extras = load_json(path)
        if not isinstance(extras, dict):
            raise CorruptDatasetError(f"{path} does not hold a JSON object; the dataset is corrupt")
        return extras

    def arrays(self, index: int) -> dict[str, np.ndarray]:
        path = self.root / ARRAYS_PATH.format(episode_index=index)
        if not path.exists():
            return {}
        return load_npz(path)

    def video(self, index: int, key: str) -> np.ndarray:
        """Decoded frames (T, H, W, 3) uint8 of one camera for one episode."""
        if not self.videos:
            raise DatasetError(f"{self.root} was opened for its tables alone (videos=False); open it "
                               "again to read its videos")
        path = self.video_path(index, key)
        row = self.episode_meta(index)
        start, stop = float(row[f"videos/{key}/from_timestamp"]), float(row[f"videos/{key}/to_timestamp"])
        frames = decode_window(path, start, stop, self.fps)  # seeks: a shared file is not decoded whole
        if len(frames) != row["length"]:
            raise CorruptDatasetError(f"{path} holds {len(frames)} frames for episode {index}, "
                                      f"expected {row['length']}; the dataset is corrupt")
        return frames
