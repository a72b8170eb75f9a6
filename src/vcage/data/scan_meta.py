"""One pass over a dataset, its metadata part: ``meta/vcage.json``, ``meta/info.json`` (or the copy of
its layout that ``meta/vcage.json`` keeps), the episode rows, the tasks and the statistics, each read
and checked against the others (:mod:`.scan` checks the episode files against them)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from vcage.data import digest, layout
from vcage.data.reader import load_json, read_parquet
from vcage.data.schema import expects_digests, schema_of
from vcage.data.verify_report import Problem, VerifyReport
from vcage.errors import CorruptDatasetError, DatasetError

_INFO_KEYS = ("codebase_version", "fps", "total_episodes", "total_frames", "features", "data_path")
_TOTALS = ("total_episodes", "total_frames", "total_tasks", "splits")


class MetaScan:
    """One pass over a dataset, its metadata part: what the metadata says (:class:`.scan.Scan` adds what
    the files hold)."""

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

    def _read_stats(self) -> None:
        path = self.root / layout.STATS_PATH
        if self.episodes == 0:
            return
        try:
            if not isinstance(load_json(path), dict):
                raise CorruptDatasetError("does not hold a JSON object")
        except DatasetError as exc:
            self.add(path, None, _reason(exc))


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
