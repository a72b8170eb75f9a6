"""LeRobot v3 dataset writer, atomic per episode, packing episodes into shared files as LeRobot does.

An episode joins the open data parquet and each camera's open mp4 (the file is rewritten with the
episode appended: parquet rows concatenated, video packets copied without re-encoding) unless that
would take one of them past ``data_files_size_in_mb`` / ``video_files_size_in_mb``; then it starts
the next file of each. Every file is written to a temporary name and moved into place; before a
file holding committed episodes is replaced, its bytes are kept under a backup name
(:func:`vcage.data.files.keep_backup`). The meta files follow (with the dataset card
``README.md``), and rewriting ``meta/info.json`` last commits the episode; then the backups go. A
failed episode is rolled back (backups restored, new files removed); a crash's leftovers are
resolved when a writer reopens the dataset (:func:`vcage.data.files.settle_backups` puts back the
committed bytes, files beyond the commit point are removed). Nothing is written before the first
episode commits, and a writer refuses to append to a dataset whose files fail the cheap checks of
:func:`vcage.data.verify.check`.
"""

from __future__ import annotations

import contextlib
import functools
import io
import json
import os
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, cast

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from vcage.data import digest, layout, video
from vcage.data import stats as st
from vcage.data.card import dataset_card
from vcage.data.files import (
    BACKUP_MARK,
    NO_SPACE,
    TMP_MARK,
    atomic_write,
    committed_episodes,
    diff,
    episode_row,
    episodes_table,
    keep_backup,
    lock_dir,
    no_space,
    remove_empty_dirs,
    restore_backup,
    scratch,
    settle_interrupted,
    tasks_table,
    to_json,
    write_json,
    write_table,
    write_text,
)
from vcage.data.reader import DTYPES, STANDARD_COLUMNS, DatasetReader, Feature, load_json, read_parquet
from vcage.data.schema import SCHEMA, schema_of
from vcage.data.verify import check
from vcage.errors import CorruptDatasetError, DatasetError


class DatasetWriter:
    """Creates a dataset at ``root``, or appends to one made with the same config, fps, features, cameras.

    Holds a lock on the dataset directory itself (``flock``, no lock file) until :meth:`close` (or
    the end of a ``with`` block). A new dataset is written by its first :meth:`add_episode`: until
    then the directory stays empty, and a writer closed without an episode removes the directory
    (and its parents) if it created them.

    ``data_files_size_in_mb`` and ``video_files_size_in_mb`` bound the shared files of a new
    dataset (LeRobot's defaults; a single episode larger than the bound gets a file of its own); an
    existing dataset keeps the bounds its ``meta/info.json`` records.
    """

    def __init__(self, root: str | Path, *, fps: int, features: Mapping[str, Feature],
                 cameras: Mapping[str, tuple[int, int]] | None = None, robot_type: str = "unknown",
                 config: Mapping[str, Any] | None = None, chunks_size: int = layout.CHUNKS_SIZE,
                 data_files_size_in_mb: float = layout.DATA_FILES_SIZE_IN_MB,
                 video_files_size_in_mb: float = layout.VIDEO_FILES_SIZE_IN_MB) -> None:
        self.root = Path(root)
        if isinstance(fps, bool) or not isinstance(fps, int) or fps <= 0:
            raise DatasetError(f"fps must be a positive integer, got {fps!r}")
        if chunks_size < 1:
            raise DatasetError(f"chunks_size must be >= 1, got {chunks_size}")
        for name, size in (("data_files_size_in_mb", data_files_size_in_mb),
                           ("video_files_size_in_mb", video_files_size_in_mb)):
            if isinstance(size, bool) or not isinstance(size, int | float) or not 0 < size < float("inf"):
                raise DatasetError(f"{name} must be a positive number of megabytes, got {size!r}")
        self.fps, self.robot_type, self.chunks_size = fps, robot_type, chunks_size
        self.file_mb = {"data": float(data_files_size_in_mb), "video": float(video_files_size_in_mb)}
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
        self._position: tuple[int, int] | None = None  # (chunk, file) of the last episode's files
        self._file_frames = 0  # frames of the committed episodes in the files at _position
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
        schema_of(load_json(self.root / layout.VCAGE_PATH), self.root)  # refuses a newer vcage's dataset
        settle_interrupted(self.root)  # an interrupted episode's replaced files: the committed bytes
        report = check(self.root).without_interrupted()  # what an interrupted write left is undone below
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
        for kind in self.file_mb:
            with contextlib.suppress(TypeError, ValueError):
                self.file_mb[kind] = float(info.get(f"{kind}_files_size_in_mb", self.file_mb[kind]))
        (self.root / layout.LEGACY_LOCK_PATH).unlink(missing_ok=True)  # older writers left it
        reader = DatasetReader(self.root)
        self._tasks = list(reader.tasks)
        self._total_episodes, self._total_frames = reader.num_episodes, reader.total_frames
        rows = [reader.episode_meta(i) for i in range(reader.num_episodes)]
        for row in rows:
            self._stats = st.merge(self._stats, st.from_row(row))
        last_chunk = (self._total_episodes - 1) // self.chunks_size
        self._chunk_rows = [r for r in rows if r["episode_index"] // self.chunks_size == last_chunk]
        if rows:
            self._resume_position(rows)
        self._remove_leftovers(rewrite_meta=reader._uncommitted)

    def _resume_position(self, rows: list[dict[str, Any]]) -> None:
        """The open files' position and the frames they hold, from the committed rows."""
        last = rows[-1]
        self._position = layout.row_position(last, "data")
        for key in self.cameras:
            if layout.row_position(last, key) != self._position:
                raise DatasetError(f"{self.root}: the last episode's {key} video is not at the position of "
                                   "its data file, as vcage writes them; append with the tool that made it")
        self._file_frames = sum(int(r["length"]) for r in rows
                                if layout.row_position(r, "data") == self._position)

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
                or layout.file_position(rel) is not None or layout.extras_episode(rel) is not None
                or rel in ours)

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
        try:
            return video.encoder_for(codecs)
        except DatasetError as exc:
            raise DatasetError(f"{self.root}: {exc}") from None

    def _remove_leftovers(self, rewrite_meta: bool) -> None:
        """Delete temporary files, backups, and episode files beyond the commit point (a crash's
        leftovers; the backups were settled before the dataset was checked)."""
        for path in sorted(self.root.rglob("*")):
            if not path.is_file():
                continue
            rel = path.relative_to(self.root).as_posix()
            found, index = layout.file_position(rel), layout.extras_episode(rel)
            hidden = path.name.startswith(".") and (TMP_MARK in path.name or BACKUP_MARK in path.name)
            beyond = found is not None and (self._position is None or found[1] > self._position)
            if hidden or beyond or (index is not None and index >= self._total_episodes):
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
                "data_files_size_in_mb": _number(self.file_mb["data"]),
                "video_files_size_in_mb": _number(self.file_mb["video"]), "fps": self.fps,
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
        write_json(self.root / layout.VCAGE_PATH, {"format": "vcage/lerobot-v3", "schema": SCHEMA,
                                                   "config": self.config, "info": static})

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
                    arrays: Mapping[str, np.ndarray] | None = None,
                    timings: dict[str, float] | None = None) -> int:
        """Write one episode and commit it; returns its index. Nothing is kept if anything fails.

        ``timings``, if given, gets the seconds spent encoding videos added under ``"encode"``."""
        if not isinstance(task, str) or not task.strip():
            raise DatasetError(f"task must be a non-empty string, got {task!r}")
        checked = self._validate(frames, videos or {})
        extras_json = to_json(dict(extras or {}), "extras")
        states = {str(k): np.asarray(v) for k, v in (arrays or {}).items()}
        if any(a.dtype == object for a in states.values()):
            raise DatasetError("arrays must be numeric numpy arrays (object arrays cannot be stored)")
        index, length = self._total_episodes, len(next(iter(checked.values())))
        tasks = self._tasks if task in self._tasks else [*self._tasks, task]
        table = self._data_table(checked, index, tasks.index(task), length)
        episode_stats = self._episode_stats(table, checked)
        chunk_rows = self._chunk_rows if index % self.chunks_size else []
        stats = st.merge(self._stats, episode_stats)
        files = _EpisodeFiles()
        meta_touched = False
        position, video_start = (0, 0), 0
        try:
            position, joined, digests = self._write_files(index, table, checked,
                                                          extras_json if extras else None, states, files,
                                                          timings)
            video_start = self._file_frames if joined else 0
            row = episode_row(index, task, length, self._total_frames, position=position,
                              video_start=video_start, chunks_size=self.chunks_size, fps=self.fps,
                              cameras=list(self.cameras), stats=episode_stats, extras=extras_json,
                              digests=digests)
            chunk_rows = [*chunk_rows, row]
            meta_touched = True
            if self._fresh and index == 0:
                self._write_marker()
            self._write_meta(tasks, chunk_rows, stats)
            frames_after = self._total_frames + length
            write_text(self.root / layout.CARD_PATH, self._card(index + 1, frames_after, tasks))
            self._write_info(index + 1, frames_after, len(tasks))
        except BaseException as exc:
            if self._committed(index + 1):  # interrupted after the commit point: the episode is in
                self._tasks, self._chunk_rows, self._stats = tasks, chunk_rows, stats
                self._advance(position, video_start + length, length)
                files.forget_backups()
            else:
                self._rollback(files, meta_touched, index)
            if isinstance(exc, OSError) and exc.errno in NO_SPACE:
                raise no_space(self.root, exc, self._total_episodes) from exc
            raise
        self._tasks, self._chunk_rows, self._stats = tasks, chunk_rows, stats
        self._advance(position, video_start + length, length)
        files.forget_backups()
        return index

    def _advance(self, position: tuple[int, int], file_frames: int, length: int) -> None:
        self._position, self._file_frames = position, file_frames
        self._total_episodes, self._total_frames = self._total_episodes + 1, self._total_frames + length

    def _joins(self, sizes: dict[str, int]) -> bool:
        """Whether an episode whose own files take ``sizes`` bytes (by data/camera key) joins the open
        files, or starts the next ones because one would grow past its size limit."""
        if self._position is None:
            return False
        for key, size in sizes.items():
            path = self._file(key, self._position)
            limit = self.file_mb["data" if key == "data" else "video"] * 1024 * 1024
            if not path.is_file() or path.stat().st_size + size > limit:
                return False
        return True

    def _file(self, key: str, position: tuple[int, int]) -> Path:
        chunk, file = position
        if key == "data":
            return self.root / layout.DATA_PATH.format(chunk_index=chunk, file_index=file)
        return self.root / layout.VIDEO_PATH.format(video_key=key, chunk_index=chunk, file_index=file)

    def _write_files(self, index: int, table: pa.Table, checked: dict[str, np.ndarray], extras: Any,
                     states: dict[str, np.ndarray], files: _EpisodeFiles,
                     timings: dict[str, float] | None = None
                     ) -> tuple[tuple[int, int], bool, dict[str, str]]:
        """Data rows, one video per camera (joined to the open files or starting the next), extras
        json and arrays npz; ``files`` records what was created or replaced. Returns the position
        of the episode's data and video files, whether it joined the open ones, and the digests of
        what it wrote (:mod:`vcage.data.digest`)."""
        buffer = pa.BufferOutputStream()
        pq.write_table(table, buffer)
        data = buffer.getvalue()
        digests = {digest.DATA: digest.of_rows(table)}
        encoded: dict[str, Path] = {}
        for key in self.cameras:  # encode first: the sizes decide whether the episode joins the open files
            scratch_dir = self.root / "videos" / key
            scratch_dir.mkdir(parents=True, exist_ok=True)
            tmp = files.scratch(scratch(scratch_dir / "episode.mp4"))
            t0 = time.perf_counter()
            video.encode_video(tmp, checked[key], fps=self.fps, encoder=self._encoder)
            if timings is not None:
                timings["encode"] = timings.get("encode", 0.0) + time.perf_counter() - t0
            encoded[key] = tmp
            window = [(0.0, len(checked[key]) / self.fps)]
            digests[digest.video_column(key)] = video.packet_digests(tmp, window, self.fps)[0]
        joined = self._joins({"data": data.size, **{k: p.stat().st_size for k, p in encoded.items()}})
        assert self._position is not None or not joined
        position = self._position if joined and self._position is not None else (
            layout.next_position(self._position, self.chunks_size) if self._position is not None else (0, 0))
        committed = self._total_episodes
        path = self._file("data", position)
        if joined:
            files.replace(path, committed, functools.partial(_append_rows, path, table))
        else:
            files.create(path, lambda tmp: tmp.write_bytes(data.to_pybytes()))
        for key, tmp_video in encoded.items():
            path = self._file(key, position)
            if joined:
                sources = [(path, 0, self._file_frames), (tmp_video, 0, len(checked[key]))]
                files.replace(path, committed, functools.partial(video.concat_videos, sources, fps=self.fps))
            else:
                files.create(path, functools.partial(os.replace, tmp_video))
        if extras is not None:
            text = json.dumps(extras, indent=1).encode()
            digests[digest.EXTRAS] = digest.of_bytes(text)
            files.create(self.root / layout.EXTRAS_PATH.format(episode_index=index),
                         lambda tmp: tmp.write_bytes(text))
        if states:
            out = io.BytesIO()
            cast(Any, np.savez_compressed)(out, **states)
            packed = out.getvalue()
            digests[digest.STATES] = digest.of_bytes(packed)
            files.create(self.root / layout.ARRAYS_PATH.format(episode_index=index),
                         lambda tmp: tmp.write_bytes(packed))
        files.remove_scratch()
        return position, joined, digests

    def _committed(self, episodes: int) -> bool:
        committed = committed_episodes(self.root)
        return committed is not None and committed >= episodes

    def _rollback(self, files: _EpisodeFiles, meta_touched: bool, index: int) -> None:
        """Undo a failed episode: put back the files it replaced, remove those it created, restore the
        meta files (best effort)."""
        files.undo()
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


class _EpisodeFiles:
    """The files one episode's write created, replaced (with their backups) and used as scratch."""

    def __init__(self) -> None:
        self.created: list[Path] = []
        self.backups: list[tuple[Path, Path]] = []  # (file, its bytes before the episode)
        self.scratches: list[Path] = []

    def scratch(self, path: Path) -> Path:
        self.scratches.append(path)
        return path

    def create(self, path: Path, write: Callable[[Path], object]) -> None:
        self.created.append(path)
        atomic_write(path, write)

    def replace(self, path: Path, committed: int, write: Callable[[Path], object]) -> None:
        """Rewrite ``path`` (which holds ``committed`` episodes' content) after keeping a backup."""
        self.backups.append((path, keep_backup(path, committed)))
        atomic_write(path, write)

    def remove_scratch(self) -> None:
        for path in self.scratches:
            path.unlink(missing_ok=True)

    def forget_backups(self) -> None:
        """The episode committed: the backups are no longer needed."""
        for _, backup in self.backups:
            with contextlib.suppress(OSError):
                backup.unlink(missing_ok=True)

    def undo(self) -> None:
        """The episode did not commit: back to the files as they were (best effort)."""
        self.remove_scratch()
        for path in self.created:
            with contextlib.suppress(OSError):
                path.unlink(missing_ok=True)
        for path, backup in self.backups:
            with contextlib.suppress(OSError):
                restore_backup(backup, path)


def _append_rows(path: Path, table: pa.Table, out: Path) -> None:
    """Write the rows of the parquet ``path`` and then ``table`` to ``out`` (columns in the order of
    the file's, which a dataset given features later, e.g. by back-filling, may have changed)."""
    old = read_parquet(path)
    if set(old.column_names) != set(table.column_names):
        raise DatasetError(f"{path} has the columns {sorted(old.column_names)}, the episode "
                           f"{sorted(table.column_names)}")
    pq.write_table(pa.concat_tables([old, table.select(old.column_names)]), out)


def _number(value: float) -> int | float:
    """A size for ``meta/info.json``: an integer when it is one (as LeRobot writes its defaults)."""
    return int(value) if float(value).is_integer() else value
