"""An episode's inputs as a dataset writer takes them: checked and cast, laid out as the data
parquet's rows, and their per-episode stats."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import pyarrow as pa

from vcage.data import stats as st
from vcage.data.reader import DTYPES, STANDARD_COLUMNS, Feature
from vcage.errors import DatasetError


class _Frames:
    """The episode arrays of :class:`vcage.data.lerobot.DatasetWriter`: validation, rows, stats."""

    fps: int
    features: dict[str, Feature]
    cameras: dict[str, tuple[int, int]]
    _total_frames: int

    def _validate(self, frames: Mapping[str, Any], videos: Mapping[str, Any]) -> dict[str, np.ndarray]:
        """Checked, cast copies of the inputs; DatasetError names the key and the shapes."""
        for given, declared, what in ((frames, self.features, "frames"), (videos, self.cameras, "videos")):
            if set(given) != set(declared):
                raise DatasetError(f"{what} keys {sorted(given)} do not match the dataset's "
                                   f"{sorted(declared)}")
        out: dict[str, np.ndarray] = {}
        for key, feature in self.features.items():
            arr = np.asarray(frames[key])
            n = feature.shape[0]
            if arr.ndim == 1 and n == 1:
                arr = arr[:, None]
            if arr.ndim != 2 or arr.shape[1] != n:
                raise DatasetError(f"frames[{key!r}] has shape {arr.shape}; feature {key!r} needs (T, {n})")
            target = np.dtype(feature.dtype)
            if not np.can_cast(arr.dtype, target, casting="same_kind"):
                raise DatasetError(f"frames[{key!r}] has dtype {arr.dtype}; feature {key!r} is "
                                   f"{feature.dtype}")
            if arr.dtype.kind == "f" and not np.isfinite(arr).all():
                raise DatasetError(f"frames[{key!r}] contains NaN or infinite values")
            out[key] = arr.astype(target)
        for key, (h, w) in self.cameras.items():
            arr = np.asarray(videos[key])
            if arr.ndim != 4 or arr.shape[1:] != (h, w, 3) or arr.dtype != np.uint8:
                raise DatasetError(f"videos[{key!r}] is {arr.dtype} {arr.shape}; camera {key!r} needs "
                                   f"uint8 (T, {h}, {w}, 3)")
            out[key] = arr
        lengths = {key: len(arr) for key, arr in out.items()}
        if len(set(lengths.values())) != 1 or min(lengths.values(), default=0) < 1:
            raise DatasetError(f"episode arrays must share one length T >= 1, got {lengths}")
        return out

    def _data_table(self, arrays: dict[str, np.ndarray], index: int, task_index: int,
                    length: int) -> pa.Table:
        columns: dict[str, pa.Array] = {}
        for key, feature in self.features.items():
            flat = pa.array(arrays[key].reshape(-1), DTYPES[feature.dtype])
            n = feature.shape[0]
            columns[key] = flat if n == 1 else pa.FixedSizeListArray.from_arrays(flat, n)
        frame_index = np.arange(length, dtype=np.int64)
        columns["timestamp"] = pa.array((frame_index / self.fps).astype(np.float32))
        columns["frame_index"] = pa.array(frame_index)
        columns["episode_index"] = pa.array(np.full(length, index, dtype=np.int64))
        columns["index"] = pa.array(frame_index + self._total_frames)
        columns["task_index"] = pa.array(np.full(length, task_index, dtype=np.int64))
        return pa.table(columns)

    def _episode_stats(self, table: pa.Table, arrays: dict[str, np.ndarray]) -> dict[str, st.Stats]:
        out = {key: st.vector_stats(arrays[key]) for key in self.features}
        out |= {key: st.image_stats(arrays[key]) for key in self.cameras}
        out |= {key: st.vector_stats(table.column(key).to_numpy()) for key in STANDARD_COLUMNS}
        return out
