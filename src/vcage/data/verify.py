"""Integrity of a dataset's files, and the repair that drops a damaged tail.

:func:`verify` checks every committed episode against the metadata that describes it: its data
parquet (readable, the expected rows, index range and frame indices), each camera's MP4 (decoded:
one frame per row within the episode's time window), its extras JSON and its states ``.npz``
(loadable, one state per frame), and the metadata itself (``meta/info.json`` totals against the
episode rows and the tasks). :func:`check` runs the cheap subset that ``vcage inspect``, ``vcage
audit``, the writer (before it appends) and the robomimic export run. :func:`repair` drops every
episode from the first damaged one to the end (LeRobot's indices must stay contiguous) and
rewrites the metadata atomically; it says what it dropped and why.

Only committed episodes are checked: files and rows beyond ``meta/info.json``'s count are a crash's
leftovers, which the writer removes when it reopens the dataset.
"""

from __future__ import annotations

import contextlib
import os
import zipfile
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from vcage.data import layout, video
from vcage.data import stats as st
from vcage.data.card import dataset_card
from vcage.data.files import (
    TMP_MARK,
    episode_row,
    episodes_table,
    lock_dir,
    remove_empty_dirs,
    tasks_table,
    write_json,
    write_table,
    write_text,
)
from vcage.data.reader import NPZ_ERRORS, STANDARD_COLUMNS, column_to_numpy, load_json, load_npz, read_parquet
from vcage.errors import CorruptDatasetError, DatasetError

_INFO_KEYS = ("codebase_version", "fps", "total_episodes", "total_frames", "features", "data_path")
_TOTALS = ("total_episodes", "total_frames", "total_tasks", "splits")


@dataclass(frozen=True)
class Problem:
    """One damage: the file (relative to the dataset root), the episodes it costs, what is wrong.

    ``episode`` is None for damage to the dataset's metadata as a whole (no episode is lost by it
    alone); ``last`` is the last episode of a range (``episode``..``last``), else equal to ``episode``.
    """

    path: str
    episode: int | None
    what: str
    last: int | None = None

    @property
    def episodes(self) -> range:
        if self.episode is None:
            return range(0)
        return range(self.episode, (self.last if self.last is not None else self.episode) + 1)

    @property
    def where(self) -> str:
        if self.episode is None:
            return "metadata"
        return _span(self.episode, self.last if self.last is not None else self.episode)

    def __str__(self) -> str:
        return f"{self.path} ({self.where}): {self.what}"


@dataclass(frozen=True)
class VerifyReport:
    """What :func:`verify` or :func:`check` found. ``episodes``: the committed episodes checked."""

    root: Path
    episodes: int
    frames: int
    decoded: bool  # videos fully decoded (verify) or only their container read (check)
    problems: tuple[Problem, ...] = ()
    repairable: bool = True  # False: :func:`repair` refuses (lost info.json without a copy, lost config)

    @property
    def ok(self) -> bool:
        return not self.problems

    @property
    def damaged(self) -> tuple[int, ...]:
        """Indices of the episodes with a problem of their own, ascending."""
        return tuple(sorted({i for p in self.problems for i in p.episodes}))

    @property
    def first_damaged(self) -> int | None:
        return self.damaged[0] if self.damaged else None

    @property
    def healthy_after_first_damaged(self) -> int:
        """Episodes without a problem that a repair drops because an earlier one is damaged."""
        first = self.first_damaged
        return 0 if first is None else self.episodes - first - len(self.damaged)

    def brief(self, limit: int = 3) -> str:
        """The problems in one line: the first ``limit`` and how many more."""
        if self.ok:
            return "no problems"
        shown = "; ".join(str(p) for p in self.problems[:limit])
        more = len(self.problems) - limit
        return f"{len(self.problems)} problem(s): {shown}" + (f"; and {more} more" if more > 0 else "")

    def summary(self) -> str:
        """Several lines: what was checked, every problem, and what ``--repair`` would drop."""
        how = "videos decoded" if self.decoded else "cheap checks: videos not decoded"
        head = f"{self.root}: {self.episodes} episodes, {self.frames} frames checked ({how})"
        if self.ok:
            return head + "; no problems"
        lines = [head + f"; {len(self.problems)} problem(s):", *(f"  {p}" for p in self.problems)]
        first = self.first_damaged
        if not self.repairable:
            lines.append("`vcage verify --repair` cannot fix this: the metadata it needs is lost; restore "
                         "the damaged metadata files from a copy")
        elif any(p.path.startswith("meta/episodes") and p.episode is not None for p in self.problems):
            lines.append("`vcage verify --repair` rebuilds the lost metadata rows from the episodes' files "
                         "where it can, then drops the episodes from the first damaged one on")
        elif first is None:
            lines.append("no episode is lost; `vcage verify --repair` rewrites the metadata")
        else:
            keeps = f"keeps {_span(0, first - 1)} and drops" if first else "drops every episode:"
            lines.append(f"`vcage verify --repair` {keeps} {_span(first, self.episodes - 1)} "
                         f"({self.healthy_after_first_damaged} of them healthy)")
        return "\n".join(lines)

    def raise_if_damaged(self) -> None:
        """CorruptDatasetError naming the damage and the repair, unless the report is clean."""
        if not self.ok:
            raise CorruptDatasetError(f"{self.root} is damaged: {self.brief()}; run `vcage verify "
                                      f"{self.root} --repair` to drop the damaged episodes")


def verify(root: str | Path) -> VerifyReport:
    """Check every committed episode's files and the metadata; decodes every video.

    Cost: linear in the dataset. It reads every parquet, extras and ``.npz`` file once and decodes
    every video once (without converting frames to RGB), which dominates: about as long as one
    decode of all the videos (seconds per thousand 128x128 frames on one core). Memory stays at
    one file's content. Raises DatasetError only if ``root`` is not a dataset at all; damage is
    reported, not raised (see :meth:`VerifyReport.raise_if_damaged`).
    """
    return _Scan(Path(root), decode=True).run().report()


def check(root: str | Path) -> VerifyReport:
    """The cheap checks: metadata, file presence, parquet footers (row counts, columns), the arrays
    in each ``.npz`` (shapes from their headers, not decompressed), extras JSON, and each video's
    box structure and container frame count (no decoding).

    Cost: a few small reads per file; no video is decoded. Catches truncated and missing files;
    damage inside a file that leaves its structure intact needs :func:`verify`.
    """
    return _Scan(Path(root), decode=False).run().report()


class _Scan:
    """The state of one pass over a dataset: what the metadata says and what the files hold."""

    def __init__(self, root: Path, decode: bool, rebuilt: dict[int, dict[str, Any]] | None = None) -> None:
        self.root, self.decode = root, decode
        self.rebuilt = rebuilt or {}  # rows rebuilt from the episode files, for rows that are lost
        self.problems: list[Problem] = []
        self.info: dict[str, Any] | None = None  # meta/info.json, if readable and complete
        self.static: dict[str, Any] | None = None  # info.json's layout part: from it or meta/vcage.json
        self.marker: dict[str, Any] | None = None  # meta/vcage.json
        self.marker_damaged = False
        self.tasks: list[str] | None = None
        self.rows: dict[int, dict[str, Any]] = {}
        self.episodes = 0
        self.row_files: dict[int, str] = {}  # episode -> the meta/episodes file that holds its row
        self.count_known = True  # False: info.json and an episodes file are both lost

    def add(self, path: Path | str, episode: int | None, what: str, last: int | None = None) -> None:
        try:
            rel = Path(path).relative_to(self.root).as_posix()
        except ValueError:
            rel = str(path)
        self.problems.append(Problem(rel, episode, what, last))

    def report(self) -> VerifyReport:
        lengths = [self.rows[i].get("length") for i in range(self.episodes) if i in self.rows]
        frames = sum(n for n in lengths if isinstance(n, int))
        order = sorted(self.problems, key=lambda p: (p.episode is not None, p.episode or 0, p.path))
        repairable = self.static is not None and self.count_known and not self.marker_damaged
        return VerifyReport(self.root, self.episodes, frames, self.decode, tuple(order), repairable)

    # metadata -------------------------------------------------------------------------------------

    def run(self) -> _Scan:
        if self.root.exists() and not self.root.is_dir():
            raise DatasetError(f"{self.root} is a file, not a dataset directory")
        info_path, marker_path = self.root / layout.INFO_PATH, self.root / layout.VCAGE_PATH
        if not info_path.exists() and not marker_path.exists():
            raise DatasetError(f"{info_path} is missing; {self.root} is not a dataset")
        self._read_marker(marker_path)
        self._read_info(info_path)
        if self.static is None:
            return self
        self._read_rows()
        self._read_tasks()
        self._check_rows()
        self._read_stats()
        self._check_data()
        self._check_videos()
        self._check_extras()
        return self

    def _read_marker(self, path: Path) -> None:
        if not path.exists():
            return
        try:
            marker = load_json(path)
        except DatasetError as exc:
            self.add(path, None, _reason(exc))
            self.marker_damaged = True
            return
        if not isinstance(marker, dict):
            self.add(path, None, "does not hold a JSON object")
            self.marker_damaged = True
            return
        self.marker = marker

    def _read_info(self, path: Path) -> None:
        try:
            if not path.exists():
                raise CorruptDatasetError("is missing")
            info = load_json(path)
            if not isinstance(info, dict):
                raise CorruptDatasetError("does not hold a JSON object")
            missing = [k for k in _INFO_KEYS if k not in info]
            if missing:
                raise CorruptDatasetError(f"lacks {', '.join(missing)}")
            int(info["total_episodes"]), int(info["total_frames"]), int(info["fps"])
            if not isinstance(info["features"], dict):
                raise CorruptDatasetError("its 'features' is not an object")
            if info["codebase_version"] != layout.CODEBASE_VERSION:
                raise DatasetError(f"{path}: codebase_version {info['codebase_version']!r} is not "
                                   f"{layout.CODEBASE_VERSION!r}; only LeRobot v3 datasets are supported")
        except CorruptDatasetError as exc:
            self.add(path, None, _reason(exc))
        except (TypeError, ValueError) as exc:
            self.add(path, None, f"mangles a required key: {exc}")
        else:
            self.info = info
            self.static = {k: v for k, v in info.items() if k not in _TOTALS}
            return
        saved = (self.marker or {}).get("info")
        if isinstance(saved, dict) and all(k in saved for k in ("fps", "features", "data_path")):
            self.static = saved  # the copy the writer keeps in meta/vcage.json

    def _read_rows(self) -> None:
        files = sorted((self.root / "meta" / "episodes").glob("chunk-*/file-*.parquet"))
        declared = int(self.info["total_episodes"]) if self.info is not None else None
        unreadable: list[str] = []
        for path in files:
            rel = path.relative_to(self.root).as_posix()
            try:
                rows = read_parquet(path).to_pylist()
            except DatasetError as exc:
                self.add(path, None, _reason(exc))
                unreadable.append(rel)
                continue
            for row in rows:
                index = row.get("episode_index")
                if isinstance(index, int) and (declared is None or 0 <= index < declared):
                    self.rows[index], self.row_files[index] = row, rel
        for index, row in self.rebuilt.items():
            if index not in self.rows and (declared is None or index < declared):
                self.rows[index] = row
                self.row_files[index] = layout.EPISODES_PATH.format(
                    chunk_index=row["meta/episodes/chunk_index"], file_index=row["meta/episodes/file_index"])
        if declared is None:  # info.json is damaged: the rows say how many episodes there are
            declared = 0
            while declared in self.rows:
                declared += 1
        self.episodes = declared
        self.count_known = self.info is not None or not unreadable
        missing = [i for i in range(declared) if i not in self.rows]
        if unreadable and missing:  # the file problems above cost these episodes: say so on them
            self.problems = [p for p in self.problems if p.path not in unreadable]
        for start, stop in _runs(missing):
            where = ", ".join(unreadable) or "meta/episodes"
            what = (f"not readable, so episodes {start}-{stop} have no metadata row" if unreadable else
                    f"no metadata row for episodes {start}-{stop}")
            self.add(where, start, what, stop)

    def _read_tasks(self) -> None:
        path = self.root / layout.TASKS_PATH
        total = int(self.info.get("total_tasks", -1)) if self.info is not None else -1
        if self.episodes == 0 and total <= 0:
            return
        try:
            table = read_parquet(path)
            by_index = dict(zip(table.column("task_index").to_pylist(), table.column("task").to_pylist(),
                                strict=True))
        except (DatasetError, KeyError) as exc:
            self.add(path, None, _reason(exc))
            return
        if total < 0:
            total = len(by_index)
        if sorted(by_index)[:total] != list(range(total)):
            self.add(path, None, f"does not hold the task indices 0-{total - 1} that {layout.INFO_PATH} "
                                 "declares")
            return
        self.tasks = [str(by_index[i]) for i in range(total)]

    def _check_rows(self) -> None:
        start = 0
        for i in range(self.episodes):
            row = self.rows.get(i)
            if row is None:
                start = -1  # after a missing row the index ranges cannot be checked
                continue
            where = self.row_files[i]
            length = row.get("length")
            if not isinstance(length, int) or length < 1:
                self.add(where, i, f"length {length!r} is not a positive integer")
                start = -1
                continue
            lo, hi = row.get("dataset_from_index"), row.get("dataset_to_index")
            if start >= 0 and lo != start:
                self.add(where, i, f"dataset_from_index {lo} != {start}, the frames of the episodes before")
            if not isinstance(lo, int) or not isinstance(hi, int) or hi - lo != length:
                self.add(where, i, f"dataset index range {lo}..{hi} does not span its length {length}")
            start = start + length if start >= 0 else -1
            tasks = row.get("tasks") or []
            if self.tasks is not None and (not tasks or tasks[0] not in self.tasks):
                self.add(where, i, f"task {tasks[:1]} is not in {layout.TASKS_PATH}")
        if self.info is not None and len(self.rows) == self.episodes:
            frames = sum(int(self.rows[i]["length"] or 0) for i in range(self.episodes))
            declared = int(self.info["total_frames"])
            if frames != declared:
                self.add(layout.INFO_PATH, None, f"says {declared} frames, the episode rows add up to "
                                                 f"{frames}")

    def _read_stats(self) -> None:
        path = self.root / layout.STATS_PATH
        if self.episodes == 0:
            return
        try:
            if not isinstance(load_json(path), dict):
                raise CorruptDatasetError("does not hold a JSON object")
        except DatasetError as exc:
            self.add(path, None, _reason(exc))

    # episode files ------------------------------------------------------------------------------

    def _grouped(self, template: str | None, fields: str, key: str | None = None) -> dict[Path, list[int]]:
        """Episode indices by the file (from ``template`` and the row's chunk/file columns) holding them."""
        out: dict[Path, list[int]] = defaultdict(list)
        if template is None:
            return out
        for i in range(self.episodes):
            row = self.rows.get(i)
            if row is None or not isinstance(row.get("length"), int):
                continue
            try:
                rel = template.format(video_key=key, chunk_index=row[f"{fields}/chunk_index"],
                                      file_index=row[f"{fields}/file_index"])
            except (KeyError, ValueError, TypeError) as exc:
                self.add(self.row_files[i], i, f"the row does not locate its file: {exc}")
                continue
            out[self.root / rel].append(i)
        return out

    def _each(self, path: Path, episodes: list[int], what: str) -> None:
        for i in episodes:
            self.add(path, i, what)

    def _check_data(self) -> None:
        assert self.static is not None
        features = [k for k, f in self.static["features"].items() if f.get("dtype") != "video"]
        for path, episodes in self._grouped(self.static.get("data_path"), "data").items():
            lengths = {i: int(self.rows[i]["length"]) for i in episodes}
            if not path.is_file():
                self._each(path, episodes, "missing")
                continue
            try:
                parquet = pq.ParquetFile(path)
                names = set(parquet.schema_arrow.names)
                rows = parquet.metadata.num_rows
            except (OSError, ValueError, pa.ArrowException) as exc:
                self._each(path, episodes, f"not a readable parquet file: {_first_line(exc)}")
                continue
            absent = sorted(set(features) - names)
            if absent:
                self._each(path, episodes, f"lacks the columns {absent}")
                continue
            if rows != sum(lengths.values()):
                self._each(path, episodes, f"holds {rows} rows, the episodes need {sum(lengths.values())}")
                continue
            if self.decode:
                self._check_table(path, episodes)

    def _check_table(self, path: Path, episodes: list[int]) -> None:
        try:
            table = pq.read_table(path)  # every column: a damaged page anywhere fails here
            columns = {name: table.column(name).to_numpy() for name in STANDARD_COLUMNS}
        except (OSError, ValueError, KeyError, pa.ArrowException) as exc:
            self._each(path, episodes, f"not a readable parquet file: {_first_line(exc)}")
            return
        for i in episodes:
            row = self.rows[i]
            mine = columns["episode_index"] == i
            length = int(row["length"])
            if int(mine.sum()) != length:
                self.add(path, i, f"holds {int(mine.sum())} frames of the episode, its row says {length}")
                continue
            start = row["dataset_from_index"]
            if not np.array_equal(columns["index"][mine], np.arange(start, start + length)):
                self.add(path, i, f"its 'index' column is not {start}..{start + length - 1}")
            if not np.array_equal(columns["frame_index"][mine], np.arange(length)):
                self.add(path, i, f"its 'frame_index' column is not 0..{length - 1}")
            task = (row.get("tasks") or [None])[0]
            if self.tasks is not None and task in self.tasks:
                found = set(columns["task_index"][mine].tolist())
                if found != {self.tasks.index(task)}:
                    self.add(path, i, f"task_index {sorted(found)} does not match its task {task!r}")

    def _check_videos(self) -> None:
        assert self.static is not None
        fps = int(self.static["fps"])
        cameras = {k: f for k, f in self.static["features"].items() if f.get("dtype") == "video"}
        for key, feature in cameras.items():
            height, width = int(feature["shape"][0]), int(feature["shape"][1])
            for path, episodes in self._grouped(self.static.get("video_path"), f"videos/{key}", key).items():
                expected = sum(int(self.rows[i]["length"]) for i in episodes)
                if not path.is_file():
                    self._each(path, episodes, "missing")
                    continue
                try:
                    probe = video.probe_video(path)
                except CorruptDatasetError as exc:
                    self._each(path, episodes, _reason(exc))
                    continue
                if (probe.height, probe.width) != (height, width):
                    self._each(path, episodes, f"frames are {probe.height}x{probe.width}, the camera "
                                               f"is {height}x{width}")
                elif probe.frames != expected:
                    self._each(path, episodes, f"its container holds {probe.frames} frames, the episodes "
                                               f"need {expected}")
                elif self.decode:
                    self._check_decoded(path, episodes, key, fps)

    def _check_decoded(self, path: Path, episodes: list[int], key: str, fps: int) -> None:
        try:
            times = video.decode_times(path)
        except CorruptDatasetError as exc:
            self._each(path, episodes, _reason(exc))
            return
        half = 0.5 / fps
        for i in episodes:
            row, length = self.rows[i], int(self.rows[i]["length"])
            try:
                start = float(row[f"videos/{key}/from_timestamp"])
                stop = float(row[f"videos/{key}/to_timestamp"])
            except (KeyError, TypeError, ValueError) as exc:
                self.add(self.row_files[i], i, f"the row lacks the time window of {key}: {exc}")
                continue
            decoded = int(((times >= start - half) & (times < stop - half)).sum())
            if decoded != length:
                self.add(path, i, f"decodes to {decoded} frames in the episode's window, expected {length}")

    def _check_extras(self) -> None:
        for i in range(self.episodes):
            row = self.rows.get(i)
            length = row.get("length") if row is not None else None
            extras = self.root / layout.EXTRAS_PATH.format(episode_index=i)
            if extras.exists():
                try:
                    if not isinstance(load_json(extras), dict):
                        raise CorruptDatasetError("does not hold a JSON object")
                except DatasetError as exc:
                    self.add(extras, i, _reason(exc))
            arrays = self.root / layout.ARRAYS_PATH.format(episode_index=i)
            if not arrays.exists():
                continue
            try:
                shapes = ({k: v.shape for k, v in load_npz(arrays).items()} if self.decode else
                          _npz_shapes(arrays))
            except (DatasetError, *NPZ_ERRORS) as exc:
                self.add(arrays, i, _reason(exc) if isinstance(exc, DatasetError) else
                         f"not a readable npz file: {_first_line(exc)}")
                continue
            states = shapes.get("states")
            if states is not None and isinstance(length, int) and (not states or states[0] != length):
                self.add(arrays, i, f"holds {states[0] if states else 0} states, the episode has {length} "
                                    "frames")


def _npz_shapes(path: Path) -> dict[str, tuple[int, ...]]:
    """The shape of each array of an ``.npz``, from the zip directory and the ``.npy`` headers only."""
    out: dict[str, tuple[int, ...]] = {}
    with zipfile.ZipFile(path) as archive:
        for name in archive.namelist():
            with archive.open(name) as member:
                version = np.lib.format.read_magic(member)
                header = (np.lib.format.read_array_header_1_0(member) if version == (1, 0) else
                          np.lib.format.read_array_header_2_0(member))
            out[name.removesuffix(".npy")] = tuple(header[0])
    return out


def _span(first: int, last: int) -> str:
    return f"episode {first}" if first == last else f"episodes {first}-{last}"


def _runs(indices: list[int]) -> list[tuple[int, int]]:
    """Consecutive runs of sorted indices as (first, last) pairs."""
    out: list[tuple[int, int]] = []
    for i in indices:
        if out and out[-1][1] == i - 1:
            out[-1] = (out[-1][0], i)
        else:
            out.append((i, i))
    return out


def _first_line(exc: BaseException) -> str:
    return (str(exc).strip().splitlines() or [type(exc).__name__])[0][:200]


def _reason(exc: BaseException) -> str:
    """A DatasetError's message without the path it starts with (the Problem names the file)."""
    text = _first_line(exc)
    head, sep, rest = text.partition(" ")
    return rest if sep and (head.startswith("/") or "/" in head) else text


# repair -------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class RepairReport:
    """What :func:`repair` did. ``kept``: the episodes the dataset holds now (0..kept-1)."""

    root: Path
    before: VerifyReport
    after: VerifyReport
    kept: int
    dropped: tuple[int, ...] = ()
    healthy_dropped: tuple[int, ...] = ()  # dropped only because an earlier episode is damaged
    rewritten: tuple[str, ...] = ()  # metadata files rewritten
    removed: tuple[str, ...] = ()  # files deleted
    reasons: dict[int, list[str]] = field(default_factory=dict)  # dropped damaged episode -> its problems
    rebuilt: tuple[int, ...] = ()  # kept episodes whose lost metadata row was rebuilt from their files

    @property
    def changed(self) -> bool:
        return bool(self.rewritten or self.removed)

    def summary(self) -> str:
        if not self.changed:
            return f"{self.root}: nothing to repair; {self.kept} episodes verified"
        kept = _span(0, self.kept - 1) if self.kept else "no episode"
        lines = [f"{self.root}: kept {kept}"]
        if self.dropped:
            lines[0] += (f", dropped {len(self.dropped)} ({_span(self.dropped[0], self.dropped[-1])}), "
                         f"{len(self.healthy_dropped)} of them healthy but after a damaged one")
            for i in sorted(self.reasons):
                lines += [f"  dropped episode {i}: {why}" for why in self.reasons[i]]
        if self.rebuilt:
            lines.append(f"  rebuilt the metadata rows of {_span(self.rebuilt[0], self.rebuilt[-1])} from "
                         "their files (image statistics from the decoded videos)")
        if self.rewritten:
            lines.append(f"  rewrote {', '.join(self.rewritten)}")
        lines.append(f"  removed {len(self.removed)} files" if self.removed else "  removed no file")
        lines.append("  verified clean afterwards" if self.after.ok else
                     f"  still damaged afterwards: {self.after.brief()}")
        return "\n".join(lines)


def repair(root: str | Path) -> RepairReport:
    """Drop every episode from the first damaged one on, and rewrite the metadata; never silently.

    Holds the writer's lock meanwhile (DatasetError if a writer is appending). Runs :func:`verify`
    (so it costs a decode of every video, twice: before and after). The episodes before the first
    damaged one are kept byte for byte; ``meta/info.json`` is rewritten first (the commit point now
    counts only the kept episodes), then ``stats.json``, ``tasks.parquet``, the episodes files and
    the card, then the dropped episodes' files are deleted, so a crash midway leaves a dataset that
    reads as the kept episodes plus leftovers the next writer removes. Damaged metadata alone
    (``stats.json``, ``tasks.parquet``, the totals in ``info.json``, or ``info.json`` itself when
    ``meta/vcage.json`` keeps a copy of its layout) is rebuilt from the episode rows.

    Raises CorruptDatasetError if the dataset cannot be repaired this way (``meta/info.json`` lost
    with no copy, ``meta/vcage.json`` unreadable). The attempt log is not touched: reconcile it with
    ``kept``.
    """
    root = Path(root)
    if not root.is_dir():
        raise DatasetError(f"{root} is not a directory; give a dataset directory")
    fd = lock_dir(root)
    try:
        scan = _Scan(root, decode=True).run()
        before = scan.report()
        if before.ok:
            return RepairReport(root, before, before, before.episodes)
        if scan.marker_damaged:
            raise CorruptDatasetError(f"cannot repair {root}: {layout.VCAGE_PATH} is damaged, and it holds "
                                      "the configuration the dataset was made with; restore it from a copy")
        if scan.static is None or not scan.count_known:
            lost = ("an episodes metadata file is damaged too, so the number of episodes is unknown"
                    if scan.static is not None else
                    f"no copy of its features is kept ({layout.VCAGE_PATH} of datasets written by older "
                    "versions has none)")
            raise CorruptDatasetError(f"cannot repair {root}: {layout.INFO_PATH} is damaged and {lost}; "
                                      "restore it from a copy")
        rebuilt = _rebuild_rows(scan)
        if rebuilt:  # an episodes file was lost: check the episodes again with their rebuilt rows
            scan = _Scan(root, decode=True, rebuilt=rebuilt).run()
        found = scan.report()
        kept = found.first_damaged if found.first_damaged is not None else found.episodes
        return _rewrite(scan, before, found, kept, tuple(i for i in sorted(rebuilt) if i < kept))
    finally:
        os.close(fd)


def _rewrite(scan: _Scan, before: VerifyReport, found: VerifyReport, kept: int,
             rebuilt: tuple[int, ...]) -> RepairReport:
    root, static = scan.root, scan.static
    assert static is not None
    rows = [scan.rows[i] for i in range(kept)]
    tasks = _kept_tasks(scan.tasks, rows)
    frames = sum(int(r["length"]) for r in rows)
    info = {**static, "total_episodes": kept, "total_frames": frames, "total_tasks": len(tasks),
            "splits": {"train": f"0:{kept}"}}
    rewritten = [layout.INFO_PATH]
    write_json(root / layout.INFO_PATH, info)  # the commit point first: nothing beyond is read now
    stats: dict[str, st.Stats] = {}
    for row in rows:
        stats = st.merge(stats, st.from_row(row))
    by_file: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for i, row in enumerate(rows):
        by_file[scan.row_files[i]].append(row)
    removed: list[str] = []
    if kept:
        write_json(root / layout.STATS_PATH, st.to_json(stats))
        write_table(root / layout.TASKS_PATH, tasks_table(tasks))
        rewritten += [layout.STATS_PATH, layout.TASKS_PATH]
        for rel, file_rows in sorted(by_file.items()):
            write_table(root / rel, episodes_table(file_rows))
            rewritten.append(rel)
    else:
        for rel in (layout.STATS_PATH, layout.TASKS_PATH):
            if (root / rel).exists():
                (root / rel).unlink()
                removed.append(rel)
    if scan.marker is not None:  # a vcage dataset: its card is vcage's (never replace another's README)
        write_text(root / layout.CARD_PATH, dataset_card(info, tasks))
        rewritten.append(layout.CARD_PATH)
    keep = _files_of(scan, range(kept))
    for path in sorted((root / "meta" / "episodes").glob("chunk-*/file-*.parquet")):
        rel = path.relative_to(root).as_posix()
        if rel not in by_file:
            path.unlink()
            removed.append(rel)
    chunks_size = int(static.get("chunks_size") or layout.CHUNKS_SIZE)
    doomed = _files_of(scan, range(kept, scan.episodes))
    for path in sorted(root.rglob("*")):
        if not path.is_file():
            continue
        rel = path.relative_to(root).as_posix()
        index = layout.episode_of_file(rel, chunks_size)
        stale = (index is not None and index >= kept) or rel in doomed or (
            path.name.startswith(".") and TMP_MARK in path.name)
        if stale and rel not in keep:
            path.unlink()
            removed.append(rel)
    for sub in ("data", "videos", "extras", "meta/episodes"):
        if (root / sub).is_dir():
            with contextlib.suppress(OSError):
                remove_empty_dirs(root / sub, keep_root=True)
    dropped = tuple(range(kept, found.episodes))
    damaged = set(found.damaged)
    reasons: dict[int, list[str]] = defaultdict(list)
    for p in found.problems:
        for i in p.episodes:
            reasons[i].append(f"{p.path}: {p.what}")
    return RepairReport(root, before, verify(root), kept, dropped,
                        tuple(i for i in dropped if i not in damaged), tuple(rewritten), tuple(removed),
                        {i: reasons[i] for i in dropped if i in damaged}, rebuilt)


def _rebuild_rows(scan: _Scan) -> dict[int, dict[str, Any]]:
    """Rows for committed episodes whose ``meta/episodes`` row is lost, rebuilt from their files.

    Only for vcage datasets (one episode per file, tasks and ``info.json`` readable), in episode
    order, up to the first episode whose files do not allow it (that one is damaged). Vector
    statistics come out exact; image statistics are taken from the decoded video, not the frames
    the writer saw, so they differ slightly from the lost ones.
    """
    static, tasks = scan.static, scan.tasks
    missing = [i for i in range(scan.episodes) if i not in scan.rows]
    if not missing or static is None or scan.info is None or scan.marker is None or tasks is None:
        return {}
    out: dict[int, dict[str, Any]] = {}
    for i in missing:
        before = scan.rows.get(i - 1) or out.get(i - 1)
        if i and before is None:
            break
        start = int(before["dataset_to_index"]) if before is not None else 0
        try:
            out[i] = _rebuild_row(scan.root, static, tasks, i, start)
        except (DatasetError, KeyError, ValueError, TypeError, *NPZ_ERRORS):
            break
    return out


def _rebuild_row(root: Path, static: dict[str, Any], tasks: list[str], index: int,
                 start: int) -> dict[str, Any]:
    chunks_size, fps = int(static.get("chunks_size") or layout.CHUNKS_SIZE), int(static["fps"])
    chunk, file = divmod(index, chunks_size)
    table = read_parquet(root / static["data_path"].format(chunk_index=chunk, file_index=file))
    if set(table.column("episode_index").to_pylist()) != {index}:
        raise CorruptDatasetError(f"the data file of episode {index} holds other episodes")
    (task_index,) = set(table.column("task_index").to_pylist())
    length = table.num_rows
    cameras = [k for k, f in static["features"].items() if f.get("dtype") == "video"]
    stats: dict[str, st.Stats] = {}
    for key, feature in static["features"].items():
        if feature.get("dtype") != "video" and key not in STANDARD_COLUMNS:
            stats[key] = st.vector_stats(column_to_numpy(table.column(key)).reshape(length, -1))
    for key in cameras:
        frames, _ = video.decode_video(root / static["video_path"].format(video_key=key, chunk_index=chunk,
                                                                          file_index=file))
        if len(frames) != length:
            raise CorruptDatasetError(f"the video {key} of episode {index} has {len(frames)} frames")
        stats[key] = st.image_stats(frames)
    for key in STANDARD_COLUMNS:
        stats[key] = st.vector_stats(table.column(key).to_numpy())
    extras_path = root / layout.EXTRAS_PATH.format(episode_index=index)
    extras = load_json(extras_path) if extras_path.exists() else None
    return episode_row(index, tasks[task_index], length, start, chunks_size=chunks_size, fps=fps,
                       cameras=cameras, stats=stats, extras=extras if isinstance(extras, dict) else None)


def _kept_tasks(tasks: list[str] | None, rows: list[dict[str, Any]]) -> list[str]:
    """The task list for the kept rows: a prefix of the existing list up to the last task they use
    (task indices in the data files stay valid), or, when ``tasks.parquet`` is lost, the tasks in
    order of first appearance (the order the writer gives them)."""
    used = [str((r.get("tasks") or [""])[0]) for r in rows]
    if tasks is not None and all(t in tasks for t in used):
        return tasks[:1 + max((tasks.index(t) for t in used), default=-1)]
    return list(dict.fromkeys(used))


def _files_of(scan: _Scan, episodes: range) -> set[str]:
    """Relative paths of the data and video files the rows of ``episodes`` point to."""
    static = scan.static
    assert static is not None
    out: set[str] = set()
    cameras = [k for k, f in static["features"].items() if f.get("dtype") == "video"]
    for i in episodes:
        row = scan.rows.get(i)
        if row is None:
            continue
        with contextlib.suppress(KeyError, ValueError, TypeError):
            out.add(static["data_path"].format(chunk_index=row["data/chunk_index"],
                                               file_index=row["data/file_index"]))
        for key in cameras:
            with contextlib.suppress(KeyError, ValueError, TypeError, AttributeError):
                out.add(static["video_path"].format(video_key=key,
                                                    chunk_index=row[f"videos/{key}/chunk_index"],
                                                    file_index=row[f"videos/{key}/file_index"]))
    return out

