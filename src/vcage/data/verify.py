"""Integrity of a dataset's files (the repair that drops a damaged tail is :mod:`.repair`).

:func:`verify` checks every committed episode against the metadata that describes it: its data
parquet (readable, the expected rows, index range and frame indices), each camera's MP4 (decoded:
one frame per row within the episode's time window), its extras JSON and its states ``.npz``
(loadable, one state per frame), and the metadata itself (``meta/info.json`` totals against the
episode rows and the tasks). :func:`check` runs the cheap subset that ``vcage inspect``, ``vcage
audit``, the writer (before it appends) and the robomimic export run.

Only committed episodes are checked: files and rows beyond ``meta/info.json``'s count are a crash's
leftovers, which the writer removes when it reopens the dataset. A shared data or video file that
an interrupted episode had already replaced is checked in the backup holding its committed bytes
(:func:`vcage.data.files.committed_version`), which the next writer or repair moves back.
"""

from __future__ import annotations

import json
import zipfile
from collections import defaultdict
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from vcage.data import digest, layout, video
from vcage.data.files import committed_version
from vcage.data.reader import NPZ_ERRORS, STANDARD_COLUMNS, load_json, load_npz, read_parquet
from vcage.data.schema import expects_digests, schema_of
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
    interrupted: bool = False  # what an interrupted write left: the next writer (or repair) undoes it

    @property
    def episodes(self) -> range:
        if self.episode is None:
            return range(0)
        return range(self.episode, (self.last if self.last is not None else self.episode) + 1)

    @property
    def where(self) -> str:
        if self.episode is None:
            return "metadata"
        return span(self.episode, self.last if self.last is not None else self.episode)

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
    keeps_intact: bool = False  # a vcage dataset: the repair keeps every intact episode, renumbered

    @property
    def ok(self) -> bool:
        return not self.problems

    def without_interrupted(self) -> VerifyReport:
        """This report without what an interrupted write left (which the next writer undoes)."""
        return replace(self, problems=tuple(p for p in self.problems if not p.interrupted))

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
        elif self.keeps_intact:
            intact = self.episodes - len(self.damaged)
            lines.append(f"`vcage verify --repair` drops the {len(self.damaged)} damaged episode(s), unless "
                         "their videos alone are damaged and render again from their stored states, and "
                         + (f"keeps the {intact} intact one(s), renumbered" if intact else "keeps no other"))
        else:
            keeps = f"keeps {span(0, first - 1)} and drops" if first else "drops every episode:"
            lines.append(f"`vcage verify --repair` {keeps} {span(first, self.episodes - 1)} "
                         f"({self.healthy_after_first_damaged} of them healthy)")
        return "\n".join(lines)

    def raise_if_damaged(self) -> None:
        """CorruptDatasetError naming the damage and the repair, unless the report is clean of all but
        what an interrupted write left (vcage's readers read the committed bytes; a plain reader of
        the files would not, which ``vcage verify`` reports)."""
        if not self.without_interrupted().ok:
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
    return Scan(Path(root), decode=True).run().report()


def check(root: str | Path) -> VerifyReport:
    """The cheap checks: metadata, file presence, parquet footers (row counts, columns), the arrays
    in each ``.npz`` (shapes from their headers, not decompressed), extras JSON, and each video's
    box structure and container frame count (no decoding).

    Cost: a few small reads per file; no video is decoded. Catches truncated and missing files;
    damage inside a file that leaves its structure intact needs :func:`verify`.
    """
    return Scan(Path(root), decode=False).run().report()


class Scan:
    """The state of one pass over a dataset: what the metadata says and what the files hold."""

    def __init__(self, root: Path, decode: bool, rebuilt: dict[int, dict[str, Any]] | None = None) -> None:
        self.root, self.decode = root, decode
        self.rebuilt = rebuilt or {}  # rows rebuilt from the episode files, for rows that are lost
        self.problems: list[Problem] = []
        self.info: dict[str, Any] | None = None  # meta/info.json, if readable and complete
        self.static: dict[str, Any] | None = None  # info.json's layout part: from it or meta/vcage.json
        self.marker: dict[str, Any] | None = None  # meta/vcage.json
        self.marker_damaged = False
        self.schema = 1  # meta/vcage.json's schema (:mod:`vcage.data.schema`)
        self.tasks: list[str] | None = None
        self.rows: dict[int, dict[str, Any]] = {}
        self.episodes = 0
        self.row_files: dict[int, str] = {}  # episode -> the meta/episodes file that holds its row
        self.count_known = True  # False: info.json and an episodes file are both lost

    def add(self, path: Path | str, episode: int | None, what: str, last: int | None = None,
            interrupted: bool = False) -> None:
        try:
            rel = Path(path).relative_to(self.root).as_posix()
        except ValueError:
            rel = str(path)
        self.problems.append(Problem(rel, episode, what, last, interrupted))

    def report(self) -> VerifyReport:
        lengths = [self.rows[i].get("length") for i in range(self.episodes) if i in self.rows]
        frames = sum(n for n in lengths if isinstance(n, int))
        order = sorted(self.problems, key=lambda p: (p.episode is not None, p.episode or 0, p.path))
        repairable = self.static is not None and self.count_known and not self.marker_damaged
        return VerifyReport(self.root, self.episodes, frames, self.decode, tuple(order), repairable,
                            keeps_intact=self.marker is not None)

    # metadata -------------------------------------------------------------------------------------

    def run(self) -> Scan:
        if self.root.exists() and not self.root.is_dir():
            raise DatasetError(f"{self.root} is a file, not a dataset directory")
        info_path, marker_path = self.root / layout.INFO_PATH, self.root / layout.VCAGE_PATH
        if not info_path.exists() and not marker_path.exists():
            raise DatasetError(f"{info_path} is missing; {self.root} is not a dataset")
        if (self.root / layout.REPAIR_PLAN).is_file():
            self.add(layout.REPAIR_PLAN, None, "a repair was interrupted after it was planned; `vcage verify "
                                               "--repair` carries it through")
        self._read_marker(marker_path)
        self._read_info(info_path)
        if self.static is None:
            return self
        self._read_rows()
        self._read_tasks()
        self._check_rows()
        self._check_digests_present()
        self._read_stats()
        self._check_data()
        self._check_videos()
        self._check_extras()
        self._check_logs()
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
        self.schema = schema_of(marker, path)  # DatasetError for a newer vcage's dataset

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
            beyond = 0
            for row in rows:
                index = row.get("episode_index")
                if isinstance(index, int) and (declared is None or 0 <= index < declared):
                    self.rows[index], self.row_files[index] = row, rel
                elif isinstance(index, int) and declared is not None and index >= declared:
                    beyond += 1
            if beyond:  # LeRobot's reader lists every row: the interrupted episode would be read
                self.add(path, None, f"holds the rows of {beyond} episode(s) whose write was interrupted "
                                     "(never committed), which a reader of the file lists; `vcage verify "
                                     "--repair` (or the next run) removes them", interrupted=True)
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

    def _source(self, path: Path, episodes: list[int]) -> Path | None:
        """The file holding ``path``'s committed bytes (see the module's docstring), or None with
        the episodes it holds marked, if it is missing."""
        if not path.is_file():
            self._each(path, episodes, "missing")
            return None
        source = committed_version(path, self.episodes)
        if source != path:  # checked in the backup; a plain reader of the file sees the episode
            self.add(path, None, "holds an episode whose write was interrupted (never committed), which "
                                 "a reader of the file sees; its committed bytes are kept beside it: "
                                 "`vcage verify --repair` (or the next run) puts them back", interrupted=True)
        return source

    def _each(self, path: Path, episodes: list[int], what: str) -> None:
        for i in episodes:
            self.add(path, i, what)

    def _check_data(self) -> None:
        assert self.static is not None
        features = [k for k, f in self.static["features"].items() if f.get("dtype") != "video"]
        for path, episodes in self._grouped(self.static.get("data_path"), "data").items():
            lengths = {i: int(self.rows[i]["length"]) for i in episodes}
            source = self._source(path, episodes)
            if source is None:
                continue
            try:
                parquet = pq.ParquetFile(source)
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
            if self.decode or any(self._recorded(i, digest.DATA) for i in episodes):
                self._check_table(path, source, episodes)

    def _check_table(self, path: Path, source: Path, episodes: list[int]) -> None:
        try:
            table = pq.read_table(source)  # every column: a damaged page anywhere fails here
            columns = {name: table.column(name).to_numpy() for name in STANDARD_COLUMNS}
        except (OSError, ValueError, KeyError, pa.ArrowException) as exc:
            self._each(path, episodes, f"not a readable parquet file: {_first_line(exc)}")
            return
        assert self.static is not None
        # the columns info.json lists: an interrupted `vcage backfill` may have added others
        committed = table.select([n for n in table.column_names if n in self.static["features"]])
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
            recorded = self._recorded(i, digest.DATA)
            if recorded is not None and digest.of_rows(committed.filter(pa.array(mine))) != recorded:
                self.add(path, i, "its rows' values differ from those written (content digest)")

    def _check_videos(self) -> None:
        assert self.static is not None
        fps = int(self.static["fps"])
        cameras = {k: f for k, f in self.static["features"].items() if f.get("dtype") == "video"}
        for key, feature in cameras.items():
            height, width = int(feature["shape"][0]), int(feature["shape"][1])
            for path, episodes in self._grouped(self.static.get("video_path"), f"videos/{key}", key).items():
                expected = sum(int(self.rows[i]["length"]) for i in episodes)
                source = self._source(path, episodes)
                if source is None:
                    continue
                try:
                    probe = video.probe_video(source)
                except CorruptDatasetError as exc:
                    self._each(path, episodes, _reason(exc))
                    continue
                if (probe.height, probe.width) != (height, width):
                    self._each(path, episodes, f"frames are {probe.height}x{probe.width}, the camera "
                                               f"is {height}x{width}")
                elif probe.frames != expected:
                    self._each(path, episodes, f"its container holds {probe.frames} frames, the episodes "
                                               f"need {expected}")
                else:
                    self._check_packets(path, source, episodes, key, fps)
                    if self.decode:
                        self._check_decoded(path, source, episodes, key, fps)

    def _recorded(self, episode: int, column: str) -> str | None:
        """The content digest ``column`` that episode ``episode``'s row recorded, or None."""
        value = self.rows[episode].get(column) if episode in self.rows else None
        return value if isinstance(value, str) else None

    def _check_digests_present(self) -> None:
        """In a dataset whose schema records content digests, a row without them has lost them (a
        row of an episode written without extras or states records none for those)."""
        if not expects_digests(self.schema):
            return
        assert self.static is not None
        cameras = [k for k, f in self.static["features"].items() if f.get("dtype") == "video"]
        needed = [digest.DATA, *(digest.video_column(k) for k in cameras)]
        for i in range(self.episodes):
            if i not in self.rows:
                continue
            lost = [c for c in needed if self._recorded(i, c) is None]
            if lost:
                self.add(self.row_files[i], i, f"its row records no content digest {', '.join(lost)}, which "
                                               f"every row of a schema-{self.schema} dataset holds")

    def _check_packets(self, path: Path, source: Path, episodes: list[int], key: str, fps: int) -> None:
        """The encoded packets in each episode's time window against the digest its row recorded."""
        column = digest.video_column(key)
        recorded = [(i, self._recorded(i, column)) for i in episodes]
        recorded = [(i, d) for i, d in recorded if d is not None]
        windows = []
        for i, _ in recorded:
            row, prefix = self.rows[i], f"videos/{key}/"
            try:
                window = (float(row[prefix + "from_timestamp"]), float(row[prefix + "to_timestamp"]))
            except (KeyError, TypeError, ValueError):
                window = (0.0, 0.0)  # its row's window is damaged: _check_decoded names it
            windows.append(window)
        if not recorded:
            return
        try:
            found = video.packet_digests(source, windows, fps)
        except CorruptDatasetError as exc:
            self._each(path, [i for i, _ in recorded], _reason(exc))
            return
        for (i, want), got in zip(recorded, found, strict=True):
            if got != want:
                self.add(path, i, "its encoded frames differ from those written (content digest)")

    def _check_decoded(self, path: Path, source: Path, episodes: list[int], key: str, fps: int) -> None:
        try:
            times = video.decode_times(source)
        except CorruptDatasetError as exc:  # damaged packets: which episodes' windows still decode?
            self._check_windows(path, source, episodes, key, fps, _reason(exc))
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

    def _check_windows(self, path: Path, source: Path, episodes: list[int], key: str, fps: int,
                       why: str) -> None:
        """Decode each episode's window alone (from the key frame it starts at), where the file as a
        whole does not decode: damaged packets cost the episodes they lie in, not every episode of
        the file."""
        for i in episodes:
            row, length = self.rows[i], int(self.rows[i]["length"])
            try:
                frames = video.decode_window(source, float(row[f"videos/{key}/from_timestamp"]),
                                             float(row[f"videos/{key}/to_timestamp"]), fps)
            except (CorruptDatasetError, KeyError, TypeError, ValueError):
                self.add(path, i, why)
                continue
            if len(frames) != length:
                self.add(path, i, f"decodes to {len(frames)} frames in the episode's window, expected "
                                  f"{length}")

    def _check_logs(self) -> None:
        """vcage's JSON-lines logs: every line but the last is JSON (a crash tears only the last one,
        which the next writer drops)."""
        for rel in (layout.ATTEMPTS_LOG, layout.RUNS_LOG):
            bad = bad_log_lines(self.root / rel)
            if bad:
                self.add(self.root / rel, None, f"{len(bad)} line(s) are not JSON (the first: line "
                                                f"{bad[0] + 1}); `vcage verify --repair` sets them aside")

    def _check_extras(self) -> None:
        """Each episode's extras JSON and states ``.npz``: readable, as long as the episode, and (where
        its row recorded a digest) present and holding the bytes written. A file's own damage is
        named first; the digest catches what leaves it readable."""
        for i in range(self.episodes):
            row = self.rows.get(i)
            length = row.get("length") if row is not None else None
            extras = self.root / layout.EXTRAS_PATH.format(episode_index=i)
            if self._present(extras, i, digest.EXTRAS):
                try:
                    if not isinstance(load_json(extras), dict):
                        raise CorruptDatasetError("does not hold a JSON object")
                except DatasetError as exc:
                    self.add(extras, i, _reason(exc))
                else:
                    self._same_bytes(extras, i, digest.EXTRAS)
            arrays = self.root / layout.ARRAYS_PATH.format(episode_index=i)
            if not self._present(arrays, i, digest.STATES):
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
                continue
            self._same_bytes(arrays, i, digest.STATES)

    def _present(self, path: Path, episode: int, column: str) -> bool:
        """Whether ``path`` exists; missing where the episode's row recorded its digest is a problem
        (an episode written without the file records none)."""
        if path.is_file():
            return True
        if self._recorded(episode, column) is not None:
            self.add(path, episode, "missing (its row records what it held)")
        return False

    def _same_bytes(self, path: Path, episode: int, column: str) -> None:
        recorded = self._recorded(episode, column)
        if recorded is not None and digest.of_file(path) != recorded:
            self.add(path, episode, "its bytes differ from those written (content digest)")


def bad_log_lines(path: Path) -> list[int]:
    """The indices of the lines of the JSON-lines file ``path`` that are not JSON, its last line left
    out (a crash while appending tears it; the writer drops it); [] if there is no file."""
    if not path.is_file():
        return []
    lines = path.read_text(errors="replace").splitlines()
    bad = []
    for n, line in enumerate(lines[:-1]):
        try:
            json.loads(line)
        except ValueError:
            bad.append(n)
    return bad


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


def span(first: int, last: int) -> str:
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
