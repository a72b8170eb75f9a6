"""LeRobot v3 dataset writer, atomic per episode.

Each episode gets its own data parquet and one mp4 per camera (chunk = index // chunks_size,
file = index % chunks_size). Files are written to a temporary name and moved into place; the meta
files follow (with the dataset card ``README.md``), and rewriting ``meta/info.json`` last commits the
episode. A failed episode is rolled back; leftovers of a crash beyond the commit point are removed
when a writer reopens the dataset. Nothing is written before the first episode commits, and a writer
refuses to append to a dataset whose files fail the cheap checks of :func:`vcage.data.verify.check`.
"""

from __future__ import annotations

import contextlib
import functools
import io
import json
import os
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, cast

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from vcage.data import layout, video
from vcage.data import stats as st
from vcage.data.card import dataset_card
from vcage.data.files import (
    TMP_MARK,
    atomic_write,
    diff,
    episode_row,
    episodes_table,
    lock_dir,
    remove_empty_dirs,
    tasks_table,
    to_json,
    write_json,
    write_table,
    write_text,
)
from vcage.data.reader import DTYPES, STANDARD_COLUMNS, DatasetReader, Feature, load_json
from vcage.data.verify import check
from vcage.errors import CorruptDatasetError, DatasetError


class DatasetWriter:
    """Creates a dataset at ``root``, or appends to one made with the same config, fps, features, cameras.

    Holds a lock on the dataset directory itself (``flock``, no lock file) until :meth:`close` (or
    the end of a ``with`` block). A new dataset is written by its first :meth:`add_episode`: until
    then the directory stays empty, and a writer closed without an episode removes the directory
    (and its parents) if it created them.
    """

    def __init__(self, root: str | Path, *, fps: int, features: Mapping[str, Feature],
                 cameras: Mapping[str, tuple[int, int]] | None = None, robot_type: str = "unknown",
                 config: Mapping[str, Any] | None = None, chunks_size: int = layout.CHUNKS_SIZE) -> None:
        self.root = Path(root)
        if isinstance(fps, bool) or not isinstance(fps, int) or fps <= 0:
            raise DatasetError(f"fps must be a positive integer, got {fps!r}")
        if chunks_size < 1:
            raise DatasetError(f"chunks_size must be >= 1, got {chunks_size}")
        self.fps, self.robot_type, self.chunks_size = fps, robot_type, chunks_size
        self.features = dict(features)
        self.cameras = {key: (int(h), int(w)) for key, (h, w) in (cameras or {}).items()}
        self.config: dict[str, Any] = to_json(dict(config or {}), "config")
        self._check_names()
        for key, (h, w) in self.cameras.items():
            video.check_frame_size(h, w, key)
        self._tasks: list[str] = []
        self._chunk_rows: list[dict[str, Any]] = []  # episode rows of the current episodes chunk file
        self._stats: dict[str, dict[str, np.ndarray]] = {}
        self._total_episodes = self._total_frames = 0
        self._lock_fd: int | None = None
        self._fresh = False  # the directory was absent or empty: the first episode creates the dataset
        self._made_dirs: list[Path] = []  # the directory and parents this writer created
        if self.root.exists() and not self.root.is_dir():
            raise DatasetError(f"{self.root} is a file; choose a directory for --out")
        parent = self.root
        while not parent.exists():
            self._made_dirs.append(parent)
            parent = parent.parent
        if not parent.is_dir():
            raise DatasetError(f"{parent} is a file, so {self.root} cannot be made a directory; choose "
                               "another --out")
        try:
            try:
                self.root.mkdir(parents=True, exist_ok=True)
            except OSError as exc:
                raise DatasetError(f"cannot create the dataset directory {self.root}: {exc.strerror}; "
                                   "choose another --out") from None
            self._lock_fd = lock_dir(self.root)
            if any(self.root.iterdir()):
                self._open_existing()
            else:
                self._fresh, self._encoder = True, video.choose_encoder() if self.cameras else ""
        except BaseException:
            self.close()
            raise

    def close(self) -> None:
        """Release the dataset lock; every added episode is already committed.

        A new dataset that got no episode is removed again: the directories this writer created,
        and any empty directory a failed first episode left, so the directory is as it was found.
        """
        if self._lock_fd is None:
            return
        try:
            if self._fresh and self._total_episodes == 0 and self.root.is_dir():
                with contextlib.suppress(OSError):
                    remove_empty_dirs(self.root, keep_root=self.root not in self._made_dirs)
                for made in self._made_dirs[1:]:
                    with contextlib.suppress(OSError):
                        made.rmdir()  # only if empty
        finally:
            os.close(self._lock_fd)
            self._lock_fd = None

    def __enter__(self) -> DatasetWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:
        with contextlib.suppress(Exception):
            self.close()

    @property
    def num_episodes(self) -> int:
        return self._total_episodes

    def _check_names(self) -> None:
        for key, feature in self.features.items():
            if not isinstance(feature, Feature):
                raise DatasetError(f"features[{key!r}] must be a Feature, got {type(feature).__name__}")
        clash = (set(self.features) | set(self.cameras)) & set(STANDARD_COLUMNS)
        both = set(self.features) & set(self.cameras)
        if clash or both:
            raise DatasetError(f"feature names {sorted(clash | both)} clash with standard columns "
                               "or cameras; rename them")

    def _signature(self) -> dict[str, Any]:
        return {"fps": self.fps, "robot_type": self.robot_type, "chunks_size": self.chunks_size,
                "features": {k: f.to_info() for k, f in self.features.items()},
                "cameras": {k: [h, w, 3] for k, (h, w) in self.cameras.items()}}

    def _open_existing(self) -> None:
        if self._uncommitted_first_episode():
            self._clear_uncommitted()
            self._fresh, self._encoder = True, video.choose_encoder() if self.cameras else ""
            return
        if (self.root / layout.VCAGE_PATH).is_file() and not (self.root / layout.INFO_PATH).exists():
            raise CorruptDatasetError(
                f"{self.root} holds {layout.VCAGE_PATH} but no {layout.INFO_PATH}: either a run was killed "
                "before its first episode committed (delete the directory to start again) or the file was "
                f"lost (`vcage verify {self.root} --repair` rebuilds it from {layout.VCAGE_PATH})")
        if not (self.root / layout.VCAGE_PATH).is_file() or not (self.root / layout.INFO_PATH).is_file():
            raise DatasetError(f"{self.root} is not empty and holds no vcage dataset (no {layout.VCAGE_PATH} "
                               f"and {layout.INFO_PATH}); choose another --out directory or an empty one")
        report = check(self.root)
        if not report.ok:
            raise CorruptDatasetError(f"refusing to append to the damaged dataset {self.root}: "
                                      f"{report.brief()}; run `vcage verify {self.root} --repair` to "
                                      "drop the damaged episodes, then append")
        info = load_json(self.root / layout.INFO_PATH)
        features = info.get("features", {})
        found = {"fps": info.get("fps"), "robot_type": info.get("robot_type"),
                 "chunks_size": info.get("chunks_size"),
                 "features": {k: v for k, v in features.items()
                              if k not in STANDARD_COLUMNS and v.get("dtype") != "video"},
                 "cameras": {k: v["shape"] for k, v in features.items() if v.get("dtype") == "video"}}
        diffs = diff(self._signature(), found)
        diffs += diff(self.config, load_json(self.root / layout.VCAGE_PATH).get("config"), "config")
        if diffs:
            shown = "; ".join(diffs[:8]) + (f"; and {len(diffs) - 8} more" if len(diffs) > 8 else "")
            raise DatasetError(f"{self.root} holds a vcage dataset made with a different configuration "
                               f"({shown}); choose another --out directory, or pass the same config to "
                               "append to it")
        self._encoder = self._encoder_for(info)
        (self.root / layout.LEGACY_LOCK_PATH).unlink(missing_ok=True)  # older writers left it
        reader = DatasetReader(self.root)
        self._tasks = list(reader.tasks)
        self._total_episodes, self._total_frames = reader.num_episodes, reader.total_frames
        rows = [reader.episode_meta(i) for i in range(reader.num_episodes)]
        for row in rows:
            self._stats = st.merge(self._stats, st.from_row(row))
        last_chunk = (self._total_episodes - 1) // self.chunks_size
        self._chunk_rows = [r for r in rows if r["episode_index"] // self.chunks_size == last_chunk]
        self._remove_leftovers(rewrite_meta=reader._uncommitted)

    def _uncommitted_first_episode(self) -> bool:
        """Whether the directory holds only what a writer killed during its first episode leaves:
        no ``info.json``, no episode rows, and nothing but files this writer writes."""
        rows = (self.root / "meta" / "episodes").rglob("*.parquet")
        if (self.root / layout.INFO_PATH).exists() or any(rows):
            return False
        return all(self._written_here(p) for p in self.root.rglob("*") if p.is_file())

    def _written_here(self, path: Path) -> bool:
        rel = path.relative_to(self.root).as_posix()
        ours = [layout.VCAGE_PATH, layout.TASKS_PATH, layout.STATS_PATH, layout.LEGACY_LOCK_PATH]
        if (self.root / layout.VCAGE_PATH).is_file():  # a README.md is the card only beside our marker
            ours.append(layout.CARD_PATH)
        return ((path.name.startswith(".") and TMP_MARK in path.name)
                or layout.episode_of_file(rel, self.chunks_size) is not None or rel in ours)

    def _clear_uncommitted(self) -> None:
        """Remove what a killed first episode left, so the run starts the dataset again."""
        for path in sorted(self.root.rglob("*"), reverse=True):
            if path.is_file():
                path.unlink()
        remove_empty_dirs(self.root, keep_root=True)

    def _encoder_for(self, info: dict[str, Any]) -> str:
        codecs = {ft["info"]["video.codec"] for ft in info["features"].values() if ft.get("dtype") == "video"}
        if not codecs:
            return ""
        for encoder in video.available_encoders():
            if video.codec_name(encoder) in codecs:
                return encoder
        raise DatasetError(f"{self.root} uses video codec {sorted(codecs)} but this PyAV build cannot "
                           "encode it; append with the environment that created the dataset")

    def _remove_leftovers(self, rewrite_meta: bool) -> None:
        """Delete temporary files and episode files beyond the commit point (a crash's leftovers)."""
        for path in sorted(self.root.rglob("*")):
            if not path.is_file():
                continue
            index = layout.episode_of_file(path.relative_to(self.root).as_posix(), self.chunks_size)
            temporary = path.name.startswith(".") and TMP_MARK in path.name
            if temporary or (index is not None and index >= self._total_episodes):
                path.unlink()
        if self._total_episodes == 0:
            for path in [self.root / layout.TASKS_PATH, self.root / layout.STATS_PATH,
                         *(self.root / "meta" / "episodes").glob("chunk-*/file-*.parquet")]:
                path.unlink(missing_ok=True)
        elif rewrite_meta:
            self._write_meta(self._tasks, self._chunk_rows, self._stats)
            write_text(self.root / layout.CARD_PATH, self._card(self._total_episodes, self._total_frames,
                                                                self._tasks))
            last_chunk = (self._total_episodes - 1) // self.chunks_size
            for path in (self.root / "meta" / "episodes").glob("chunk-*/file-*.parquet"):
                if int(path.parent.name.split("-")[1]) > last_chunk:
                    path.unlink()

    def _info(self, episodes: int, frames: int, tasks: int) -> dict[str, Any]:
        features: dict[str, Any] = {k: f.to_info() for k, f in self.features.items()}
        codec = video.codec_name(self._encoder) if self._encoder else None
        for key, (h, w) in self.cameras.items():
            features[key] = {"dtype": "video", "shape": [h, w, 3], "names": ["height", "width", "channels"],
                             "info": {"video.height": h, "video.width": w, "video.codec": codec,
                                      "video.pix_fmt": video.PIX_FMT, "video.is_depth_map": False,
                                      "video.fps": self.fps, "video.channels": 3, "has_audio": False}}
        for key, dtype in STANDARD_COLUMNS.items():
            features[key] = {"dtype": dtype, "shape": [1], "names": None}
        info = {"codebase_version": layout.CODEBASE_VERSION, "robot_type": self.robot_type,
                "total_episodes": episodes, "total_frames": frames, "total_tasks": tasks,
                "chunks_size": self.chunks_size,
                "data_files_size_in_mb": 100, "video_files_size_in_mb": 200, "fps": self.fps,
                "splits": {"train": f"0:{episodes}"}, "data_path": layout.DATA_PATH,
                "video_path": layout.VIDEO_PATH if self.cameras else None, "features": features}
        return info

    def _write_info(self, episodes: int, frames: int, tasks: int) -> None:
        write_json(self.root / layout.INFO_PATH, self._info(episodes, frames, tasks))

    def _card(self, episodes: int, frames: int, tasks: list[str]) -> str:
        return dataset_card(self._info(episodes, frames, len(tasks)), tasks)

    def _write_marker(self) -> None:
        """``meta/vcage.json``: the format, the config, and ``meta/info.json`` without its totals (so
        that :func:`vcage.data.repair.repair` can rebuild a damaged ``info.json``)."""
        static = {k: v for k, v in self._info(0, 0, 0).items()
                  if k not in ("total_episodes", "total_frames", "total_tasks", "splits")}
        write_json(self.root / layout.VCAGE_PATH, {"format": "vcage/lerobot-v3", "config": self.config,
                                                   "info": static})

    def _write_meta(self, tasks: list[str], chunk_rows: list[dict[str, Any]],
                    stats: dict[str, dict[str, np.ndarray]]) -> None:
        """tasks.parquet, the episodes file of ``chunk_rows`` and stats.json (not yet the commit)."""
        write_table(self.root / layout.TASKS_PATH, tasks_table(tasks))
        chunk = chunk_rows[-1]["episode_index"] // self.chunks_size
        write_table(self.root / layout.EPISODES_PATH.format(chunk_index=chunk, file_index=0),
                    episodes_table(chunk_rows))
        write_json(self.root / layout.STATS_PATH, st.to_json(stats))

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

    def add_episode(self, frames: Mapping[str, Any], videos: Mapping[str, Any] | None = None, *, task: str,
                    extras: Mapping[str, Any] | None = None,
                    arrays: Mapping[str, np.ndarray] | None = None) -> int:
        """Write one episode and commit it; returns its index. Nothing is kept if anything fails."""
        if not isinstance(task, str) or not task.strip():
            raise DatasetError(f"task must be a non-empty string, got {task!r}")
        checked = self._validate(frames, videos or {})
        extras_json = to_json(dict(extras or {}), "extras")
        states = {str(k): np.asarray(v) for k, v in (arrays or {}).items()}
        if any(a.dtype == object for a in states.values()):
            raise DatasetError("arrays must be numeric numpy arrays (object arrays cannot be stored)")
        index, length = self._total_episodes, len(next(iter(checked.values())))
        chunk, file = divmod(index, self.chunks_size)
        tasks = self._tasks if task in self._tasks else [*self._tasks, task]
        table = self._data_table(checked, index, tasks.index(task), length)
        episode_stats = self._episode_stats(table, checked)
        row = episode_row(index, task, length, self._total_frames, chunks_size=self.chunks_size, fps=self.fps,
                          cameras=list(self.cameras), stats=episode_stats, extras=extras_json)
        chunk_rows = [*(self._chunk_rows if file else []), row]
        stats = st.merge(self._stats, episode_stats)
        written: list[Path] = []
        meta_touched = False

        def commit() -> None:
            self._tasks, self._chunk_rows, self._stats = tasks, chunk_rows, stats
            self._total_episodes, self._total_frames = index + 1, self._total_frames + length

        try:
            self._write_files(index, table, checked, extras_json if extras else None, states, written)
            meta_touched = True
            if self._fresh and index == 0:
                self._write_marker()
            self._write_meta(tasks, chunk_rows, stats)
            frames_after = self._total_frames + length
            write_text(self.root / layout.CARD_PATH, self._card(index + 1, frames_after, tasks))
            self._write_info(index + 1, frames_after, len(tasks))
        except BaseException:
            if self._committed(index + 1):  # interrupted after the commit point: the episode is in
                commit()
            else:
                self._rollback(written, meta_touched, index)
            raise
        commit()
        return index

    def _write_files(self, index: int, table: pa.Table, checked: dict[str, np.ndarray], extras: Any,
                     states: dict[str, np.ndarray], written: list[Path]) -> None:
        """Data parquet, one mp4 per camera, extras json and arrays npz; ``written`` lists them."""
        chunk, file = divmod(index, self.chunks_size)

        def put(path: Path, write: Callable[[Path], object]) -> None:
            written.append(path)
            atomic_write(path, write)

        put(self.root / layout.DATA_PATH.format(chunk_index=chunk, file_index=file),
            lambda tmp: pq.write_table(table, tmp))
        for key in self.cameras:
            path = self.root / layout.VIDEO_PATH.format(video_key=key, chunk_index=chunk, file_index=file)
            put(path, functools.partial(video.encode_video, frames=checked[key], fps=self.fps,
                                        encoder=self._encoder))
        if extras is not None:
            text = json.dumps(extras, indent=1)
            put(self.root / layout.EXTRAS_PATH.format(episode_index=index), lambda tmp: tmp.write_text(text))
        if states:
            def save(tmp: Path) -> None:
                buffer = io.BytesIO()
                cast(Any, np.savez_compressed)(buffer, **states)
                tmp.write_bytes(buffer.getvalue())

            put(self.root / layout.ARRAYS_PATH.format(episode_index=index), save)

    def _committed(self, episodes: int) -> bool:
        with contextlib.suppress(Exception):
            return int(load_json(self.root / layout.INFO_PATH)["total_episodes"]) >= episodes
        return False

    def _rollback(self, written: list[Path], meta_touched: bool, index: int) -> None:
        """Undo a failed episode: remove its files and restore the meta files (best effort)."""
        for path in written:
            with contextlib.suppress(OSError):
                path.unlink(missing_ok=True)
        if not meta_touched:
            return
        with contextlib.suppress(Exception):
            if self._total_episodes:
                self._write_meta(self._tasks, self._chunk_rows, self._stats)
                write_text(self.root / layout.CARD_PATH, self._card(self._total_episodes, self._total_frames,
                                                                    self._tasks))
            else:
                (self.root / layout.TASKS_PATH).unlink(missing_ok=True)
                (self.root / layout.STATS_PATH).unlink(missing_ok=True)
                (self.root / layout.CARD_PATH).unlink(missing_ok=True)
                if self._fresh:
                    (self.root / layout.VCAGE_PATH).unlink(missing_ok=True)
            if index % self.chunks_size == 0:
                chunk = index // self.chunks_size
                episodes = self.root / layout.EPISODES_PATH.format(chunk_index=chunk, file_index=0)
                episodes.unlink(missing_ok=True)
