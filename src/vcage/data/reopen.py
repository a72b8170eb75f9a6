"""Opening an existing dataset to append to it: the configuration compared, the cheap checks run,
a crash's leftovers resolved, and the writer's state resumed from the committed episodes."""

from __future__ import annotations

import contextlib
from pathlib import Path
from typing import Any

import numpy as np

from vcage.data import layout, video
from vcage.data import stats as st
from vcage.data.files import BACKUP_MARK, TMP_MARK, diff, remove_empty_dirs, settle_interrupted, write_text
from vcage.data.meta import _MetaFiles
from vcage.data.reader import STANDARD_COLUMNS, DatasetReader, load_json
from vcage.data.schema import schema_of
from vcage.data.verify import check
from vcage.errors import CorruptDatasetError, DatasetError


class _Reopening(_MetaFiles):
    """How :class:`vcage.data.lerobot.DatasetWriter` opens a directory that already holds files."""

    _fresh: bool
    _tasks: list[str]
    _chunk_rows: list[dict[str, Any]]
    _stats: dict[str, dict[str, np.ndarray]]
    _total_episodes: int
    _total_frames: int
    _position: tuple[int, int] | None
    _file_frames: int

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
