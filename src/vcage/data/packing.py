"""Packing an episode's files into a dataset's shared files: the episode joins the open data parquet
and videos, or starts the next ones when a file would grow past its size limit."""

from __future__ import annotations

import functools
import io
import json
import os
import time
from pathlib import Path
from typing import Any, cast

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from vcage.data import digest, layout, video
from vcage.data.episode_files import _EpisodeFiles
from vcage.data.files import scratch
from vcage.data.reader import read_parquet
from vcage.errors import DatasetError


class _Packing:
    """Where :class:`vcage.data.lerobot.DatasetWriter` writes an episode's files, and writing them."""

    root: Path
    fps: int
    chunks_size: int
    file_mb: dict[str, float]
    cameras: dict[str, tuple[int, int]]
    _encoder: str
    _total_episodes: int
    _position: tuple[int, int] | None
    _file_frames: int

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


def _append_rows(path: Path, table: pa.Table, out: Path) -> None:
    """Write the rows of the parquet ``path`` and then ``table`` to ``out`` (columns in the order of
    the file's, which a dataset given features later, e.g. by back-filling, may have changed)."""
    old = read_parquet(path)
    if set(old.column_names) != set(table.column_names):
        raise DatasetError(f"{path} has the columns {sorted(old.column_names)}, the episode "
                           f"{sorted(table.column_names)}")
    pq.write_table(pa.concat_tables([old, table.select(old.column_names)]), out)
