"""One pass over a dataset, its episode files: each committed episode's data parquet, camera MP4s,
extras JSON and states ``.npz``, checked against the metadata that :mod:`.scan_meta` reads, and
vcage's logs.

A shared data or video file that an interrupted episode had already replaced is checked in the
backup holding its committed bytes (:func:`vcage.data.files.committed_version`), which the next
writer or repair moves back.
"""

from __future__ import annotations

import json
import zipfile
from collections import defaultdict
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from vcage.data import digest, layout, video
from vcage.data.files import committed_version
from vcage.data.reader import NPZ_ERRORS, STANDARD_COLUMNS, load_json, load_npz
from vcage.data.scan_meta import MetaScan, _first_line, _reason
from vcage.errors import CorruptDatasetError, DatasetError


class Scan(MetaScan):
    """The state of one pass over a dataset: what the metadata says and what the files hold."""

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
