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
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from vcage.data import layout, video
from vcage.data import stats as st
from vcage.data.episode_files import _EpisodeFiles
from vcage.data.files import (
    NO_SPACE,
    committed_episodes,
    episode_row,
    lock_dir,
    no_space,
    remove_empty_dirs,
    to_json,
    write_text,
)
from vcage.data.frames import _Frames
from vcage.data.meta import _MetaFiles
from vcage.data.packing import _Packing
from vcage.data.reader import STANDARD_COLUMNS, Feature
from vcage.data.reopen import _Reopening
from vcage.errors import DatasetError


class DatasetWriter(_Reopening, _Packing, _Frames, _MetaFiles):
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
