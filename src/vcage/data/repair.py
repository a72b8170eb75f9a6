"""Repair of a damaged dataset: drop the damaged episodes, keep every intact one.

In a vcage dataset the intact episodes after a damaged one are kept, renumbered so that LeRobot's
episode indices stay contiguous, and an episode whose only damage is in its videos is rendered
again from its stored states where that reproduces them exactly (:mod:`.compact`). In another
LeRobot dataset the episodes from the first damaged one to the end are dropped. The metadata that
a lost or damaged meta file held is rebuilt from the episodes' own files where it can be, and the
result is checked again. Nothing is dropped silently: the report names every dropped episode and
why, and nothing is deleted: what the repair takes out goes to ``quarantine/<time>/``.
"""

from __future__ import annotations

import contextlib
import functools
import os
import shutil
import time
from collections import defaultdict
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import pyarrow.compute as pc

from vcage.data import digest, layout, video
from vcage.data import stats as st
from vcage.data.card import dataset_card
from vcage.data.compact import Render, compact, finish, info_for, kept_tasks, stats_for
from vcage.data.files import (
    BACKUP_MARK,
    TMP_MARK,
    atomic_write,
    episode_row,
    episodes_table,
    lock_dir,
    remove_empty_dirs,
    settle_interrupted,
    tasks_table,
    write_json,
    write_table,
    write_text,
)
from vcage.data.reader import NPZ_ERRORS, STANDARD_COLUMNS, column_to_numpy, load_json, read_parquet
from vcage.data.verify import Scan, VerifyReport, bad_log_lines, span, verify
from vcage.errors import CorruptDatasetError, DatasetError


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
    restored: tuple[str, ...] = ()  # files an interrupted write had replaced, given their committed bytes
    quarantine: str | None = None  # where what was removed or cut was set aside (relative to root)
    renumbered: dict[int, int] = field(default_factory=dict)  # kept episode's old index -> new index
    rerendered: tuple[int, ...] = ()  # kept after their videos were rendered again from their states
    resumed: bool = False  # an interrupted repair was carried through first
    compacted: bool = False  # the intact episodes were kept, renumbered (:mod:`.compact`)

    @property
    def changed(self) -> bool:
        return bool(self.rewritten or self.removed or self.restored or self.resumed)

    def summary(self) -> str:
        if not self.changed:
            return f"{self.root}: nothing to repair; {self.kept} episodes verified"
        kept = span(0, self.kept - 1) if self.kept else "no episode"
        lines = [f"{self.root}: kept {kept}"]
        if self.resumed:
            lines.insert(0, f"{self.root}: carried an interrupted repair through")
        if self.dropped and (self.renumbered or not self.healthy_dropped):
            lines[-1] += f", dropped {len(self.dropped)} damaged ({_list(self.dropped)})"
        elif self.dropped:
            lines[-1] += (f", dropped {len(self.dropped)} ({span(self.dropped[0], self.dropped[-1])}), "
                          f"{len(self.healthy_dropped)} of them healthy but after a damaged one")
        if self.dropped:
            for i in sorted(self.reasons):
                lines += [f"  dropped episode {i}: {why}" for why in self.reasons[i]]
        if self.renumbered:
            moves = sorted(self.renumbered.items())
            lines.append(f"  renumbered {len(moves)} intact episodes ({moves[0][0]} is now {moves[0][1]}"
                         + (f", ..., {moves[-1][0]} is now {moves[-1][1]}" if len(moves) > 1 else "")
                         + "); their content is unchanged")
        if self.rerendered:
            lines.append(f"  rendered the videos of {_list(self.rerendered)} again from their stored states "
                         "(the encoded frames match those written)")
        if self.rebuilt:
            lines.append(f"  rebuilt the metadata rows of {span(self.rebuilt[0], self.rebuilt[-1])} from "
                         "their files (image statistics from the decoded videos)")
        if self.restored:
            lines.append(f"  put back the committed bytes of {', '.join(self.restored)} (an interrupted "
                         "write had replaced them)")
        if self.rewritten:
            lines.append(f"  rewrote {', '.join(self.rewritten)}")
        if self.quarantine and self.compacted:
            lines.append(f"  set aside the {len(self.removed)} files it dropped or replaced, as they were, "
                         f"in {self.quarantine}/ (NOTE.md there says why; nothing was deleted)")
        elif self.quarantine:
            lines.append(f"  set aside {len(self.removed)} files and the shared files as they were before "
                         f"the cut in {self.quarantine}/ (NOTE.md there says why; nothing was deleted)")
        else:
            lines.append(f"  removed {len(self.removed)} files" if self.removed else "  removed no file")
        lines.append("  verified clean afterwards" if self.after.ok else
                     f"  still damaged afterwards: {self.after.brief()}")
        return "\n".join(lines)


def repair(root: str | Path, render: Render | None = None) -> RepairReport:
    """Drop the damaged episodes, and rewrite the metadata; never silently.

    In a vcage dataset (``meta/vcage.json``) every intact episode is kept, renumbered, by
    :func:`vcage.data.compact.compact` (crash-safe; an interrupted repair is carried through first),
    and ``render`` (an episode's extras and states -> its frames), when given, renders again the
    videos of episodes damaged in their videos alone. The rest of this docstring is the repair of
    another LeRobot dataset, and of damaged metadata alone:

    Holds the writer's lock meanwhile (DatasetError if a writer is appending). Runs :func:`verify`
    (so it costs a decode of every video, twice: before and after). The episodes before the first
    damaged one are kept: their files byte for byte, except a data or video file they share with
    dropped episodes, which is cut after the last kept episode (rows filtered, video packets copied
    without re-encoding) before anything else, so a crash there leaves the dropped episodes damaged
    and the kept ones intact. Then ``meta/info.json`` is rewritten (the commit point now counts only
    the kept episodes), then ``stats.json``, ``tasks.parquet``, the episodes files and the card,
    then the dropped episodes' files are deleted, so a crash midway leaves a dataset that reads as
    the kept episodes plus leftovers the next writer removes. Damaged metadata alone
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
        resumed = finish(root)
        before = Scan(root, decode=True).run().report()  # as a reader finds it, interrupted writes included
        restored = [p.relative_to(root).as_posix() for p in settle_interrupted(root)]  # the committed bytes
        scan = Scan(root, decode=True).run()
        if scan.report().ok:
            leftovers = _remove_scratch(root)
            after = verify(root) if restored or leftovers or resumed else before
            return RepairReport(root, before, after, after.episodes, removed=tuple(leftovers),
                                restored=tuple(restored), resumed=resumed)
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
            scan = Scan(root, decode=True, rebuilt=rebuilt).run()
        found = scan.report()
        if found.damaged and scan.marker is not None:
            return _compact(scan, before, found, render, tuple(restored), resumed)
        kept = found.first_damaged if found.first_damaged is not None else found.episodes
        report = _rewrite(scan, before, found, kept, tuple(i for i in sorted(rebuilt) if i < kept))
        return replace(report, restored=tuple(restored), resumed=resumed)
    finally:
        os.close(fd)


def _compact(scan: Scan, before: VerifyReport, found: VerifyReport, render: Render | None,
             restored: tuple[str, ...], resumed: bool) -> RepairReport:
    root = scan.root
    rewritten, scratch = _set_aside_bad_lines(root), _remove_scratch(root)
    aside = Quarantine(root)
    done = compact(scan, found, aside.folder(), render)
    rebuilt = tuple(sorted(i for i in scan.rebuilt if i not in done.dropped))
    return RepairReport(root, before, verify(root), done.kept, done.dropped, (), (*rewritten, *done.put),
                        (*done.aside, *scratch), done.reasons, rebuilt, restored, aside.folder(),
                        done.renumbered, done.rerendered, resumed, compacted=True)


def _list(indices: tuple[int, ...]) -> str:
    more = f" and {len(indices) - 8} more" if len(indices) > 8 else ""
    return ", ".join(str(i) for i in indices[:8]) + more


def _rewrite(scan: Scan, before: VerifyReport, found: VerifyReport, kept: int,
             rebuilt: tuple[int, ...]) -> RepairReport:
    root, static = scan.root, scan.static
    assert static is not None
    rows = [scan.rows[i] for i in range(kept)]
    tasks = kept_tasks(scan.tasks, rows)
    info = info_for(static, rows, tasks)
    keep = _files_of(scan, range(kept))
    doomed = _files_of(scan, range(kept, scan.episodes))
    aside = Quarantine(root)
    for rel in sorted(keep & doomed):  # the dropped episodes' part of a shared file is kept there
        aside.copy(rel)
    rewritten = [*_cut_shared(scan, kept, sorted(keep & doomed)), *_set_aside_bad_lines(root),
                 layout.INFO_PATH]
    write_json(root / layout.INFO_PATH, info)  # the commit point: nothing beyond is read now
    by_file: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for i, row in enumerate(rows):
        by_file[scan.row_files[i]].append(row)
    removed: list[str] = []
    if kept:
        write_json(root / layout.STATS_PATH, st.to_json(stats_for(rows)))
        write_table(root / layout.TASKS_PATH, tasks_table(tasks))
        rewritten += [layout.STATS_PATH, layout.TASKS_PATH]
        for rel, file_rows in sorted(by_file.items()):
            write_table(root / rel, episodes_table(file_rows))
            rewritten.append(rel)
    else:
        for rel in (layout.STATS_PATH, layout.TASKS_PATH):
            if (root / rel).exists():
                aside.move(rel)
                removed.append(rel)
    if scan.marker is not None:  # a vcage dataset: its card is vcage's (never replace another's README)
        write_text(root / layout.CARD_PATH, dataset_card(info, tasks))
        rewritten.append(layout.CARD_PATH)
    for path in sorted((root / "meta" / "episodes").glob("chunk-*/file-*.parquet")):
        rel = path.relative_to(root).as_posix()
        if rel not in by_file:
            if any(scan.row_files.get(i) == rel for i in range(kept, scan.episodes)):
                aside.move(rel)  # rows of committed episodes the repair drops
            else:
                path.unlink()  # rows beyond the commit point: an interrupted write's
            removed.append(rel)
    last = rows[-1] if rows else None
    for path in sorted(root.rglob("*")):
        if not path.is_file() or path.is_relative_to(root / QUARANTINE):
            continue
        rel = path.relative_to(root).as_posix()
        index, position = layout.extras_episode(rel), layout.file_position(rel)
        hidden = path.name.startswith(".") and (TMP_MARK in path.name or BACKUP_MARK in path.name)
        stale = (index is not None and index >= kept) or rel in doomed or hidden or (
            position is not None and _beyond(position, last))
        if stale and rel not in keep:
            if rel in doomed or (index is not None and kept <= index < scan.episodes):
                aside.move(rel)  # a file of a committed episode the repair drops
            else:
                path.unlink()  # a temporary file, a settled backup or an interrupted write's leftover
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
    note = aside.note(found, kept, dropped)
    return RepairReport(root, before, verify(root), kept, dropped,
                        tuple(i for i in dropped if i not in damaged), tuple(rewritten), tuple(removed),
                        {i: reasons[i] for i in dropped if i in damaged}, rebuilt, quarantine=note)


QUARANTINE = "quarantine"  # inside the dataset; LeRobot and vcage's readers never look there


class Quarantine:
    """Where a repair sets aside what it removes from the dataset or cuts out of a shared file:
    ``quarantine/<time>/`` inside it, the files under their own paths, and ``NOTE.md`` saying why.
    Created on first use; nothing is deleted."""

    def __init__(self, root: Path) -> None:
        self.root = root
        self.dir: Path | None = None
        self.entries: list[str] = []

    def folder(self) -> str:
        """The folder (relative to the dataset) this repair sets aside into; chosen on first call."""
        if self.dir is None:
            stamp = time.strftime("%Y%m%d-%H%M%S")
            base = self.root / QUARANTINE / stamp
            k = 1
            while base.exists():
                k += 1
                base = self.root / QUARANTINE / f"{stamp}-{k}"
            self.dir = base
        return self.dir.relative_to(self.root).as_posix()

    def _target(self, rel: str) -> Path:
        out = self.root / self.folder() / rel
        out.parent.mkdir(parents=True, exist_ok=True)
        return out

    def copy(self, rel: str) -> None:
        """Keep the file at ``rel`` as it is now (before a repair cuts it)."""
        if (self.root / rel).is_file():
            shutil.copyfile(self.root / rel, self._target(rel))
            self.entries.append(f"{rel}: as it was before the repair cut it")

    def move(self, rel: str) -> None:
        os.replace(self.root / rel, self._target(rel))
        self.entries.append(f"{rel}: removed from the dataset")

    def note(self, found: VerifyReport, kept: int, dropped: tuple[int, ...]) -> str | None:
        """Write ``NOTE.md``; the folder relative to the dataset, or None where nothing was set aside."""
        if self.dir is None:
            return None
        lines = [f"# Set aside by `vcage verify --repair` on {time.strftime('%Y-%m-%d %H:%M:%S')}", "",
                 f"The dataset kept {span(0, kept - 1) if kept else 'no episode'}"
                 + (f" and dropped {span(dropped[0], dropped[-1])}." if dropped else "."), "",
                 "What verify found:", "", *(f"- {p}" for p in found.problems), "", "Files here:", "",
                 *(f"- {e}" for e in self.entries), ""]
        (self.dir / "NOTE.md").write_text("\n".join(lines))
        return self.dir.relative_to(self.root).as_posix()


def _remove_scratch(root: Path) -> list[str]:
    """Delete the temporary files an interrupted write left (hidden, marked ``.tmp-``); their names."""
    out = []
    for path in sorted(root.rglob(f".*{TMP_MARK}*")):
        if path.is_file():
            path.unlink()
            out.append(path.relative_to(root).as_posix())
    return out


def _set_aside_bad_lines(root: Path) -> list[str]:
    """Rewrite each vcage log without the lines that are not JSON, which go to a ``.damaged-<time>``
    file beside it (nothing is deleted); the logs rewritten."""
    out = []
    for rel in (layout.ATTEMPTS_LOG, layout.RUNS_LOG):
        path = root / rel
        bad = set(bad_log_lines(path))
        if not bad:
            continue
        lines = path.read_text(errors="replace").splitlines(keepends=True)
        stamp = time.strftime("%Y%m%d-%H%M%S")
        write_text(path.with_name(f"{path.name}.damaged-{stamp}"), "".join(lines[i] for i in sorted(bad)))
        write_text(path, "".join(line for i, line in enumerate(lines) if i not in bad))
        out.append(rel)
    return out


def _beyond(found: tuple[str, tuple[int, int]], last: dict[str, Any] | None) -> bool:
    """Whether a data or video file lies after the files of the last kept episode's row."""
    if last is None:
        return True
    key, position = found
    try:
        return position > layout.row_position(last, key)
    except (KeyError, ValueError, TypeError):
        return False  # a camera the rows do not know: not vcage's to delete


def _cut_shared(scan: Scan, kept: int, shared: list[str]) -> list[str]:
    """Cut the data and video files that hold kept and dropped episodes after the last kept one."""
    static = scan.static
    assert static is not None
    fps = int(static["fps"])
    cameras = [k for k, f in static["features"].items() if f.get("dtype") == "video"]
    out = []
    for rel in shared:
        found = layout.file_position(rel)
        if found is None:
            continue
        key, position = found
        path = scan.root / rel
        if key == "data":
            table = read_parquet(path)
            table = table.filter(pc.less(table.column("episode_index"), kept))
            write_table(path, table)
        elif key in cameras:
            frames = sum(int(scan.rows[i]["length"]) for i in range(kept)
                         if layout.row_position(scan.rows[i], key) == position)
            atomic_write(path, functools.partial(video.concat_videos, [(path, 0, frames)], fps=fps))
        out.append(rel)
    return out


def _rebuild_rows(scan: Scan) -> dict[int, dict[str, Any]]:
    """Rows for committed episodes whose ``meta/episodes`` row is lost, rebuilt from their files.

    Only for vcage datasets (data and videos at the same position, tasks and ``info.json``
    readable), in episode order, up to the first episode whose files do not allow it (that one is
    damaged). Vector statistics come out exact; image statistics are taken from the decoded video,
    not the frames the writer saw, so they differ slightly from the lost ones.
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
        try:
            out[i] = _rebuild_row(scan.root, static, tasks, i, before)
        except (DatasetError, KeyError, ValueError, TypeError, *NPZ_ERRORS):
            break
    return out


def _rebuild_row(root: Path, static: dict[str, Any], tasks: list[str], index: int,
                 before: dict[str, Any] | None) -> dict[str, Any]:
    """The row of episode ``index``, found in the data file of the episode ``before`` it or the next."""
    chunks_size, fps = int(static.get("chunks_size") or layout.CHUNKS_SIZE), int(static["fps"])
    first = layout.row_position(before, "data") if before is not None else (0, 0)
    for position in (first, layout.next_position(first, chunks_size)):
        path = root / static["data_path"].format(chunk_index=position[0], file_index=position[1])
        if path.is_file():
            full = read_parquet(path)
            episodes = full.column("episode_index").to_numpy()
            if (episodes == index).any():
                break
    else:
        raise CorruptDatasetError(f"no data file holds episode {index}")
    table = full.filter(pc.equal(full.column("episode_index"), index))
    video_start = int((episodes < index).sum())  # frames of the episodes before it in the same files
    (task_index,) = set(table.column("task_index").to_pylist())
    length = table.num_rows
    cameras = [k for k, f in static["features"].items() if f.get("dtype") == "video"]
    stats: dict[str, st.Stats] = {}
    for key, feature in static["features"].items():
        if feature.get("dtype") != "video" and key not in STANDARD_COLUMNS:
            stats[key] = st.vector_stats(column_to_numpy(table.column(key)).reshape(length, -1))
    # the row is lost with the digests it recorded: they are taken again from the files as they are
    committed = table.select([n for n in table.column_names if n in static["features"]])
    digests = {digest.DATA: digest.of_rows(committed)}
    for key in cameras:
        chunk, file = position
        path = root / static["video_path"].format(video_key=key, chunk_index=chunk, file_index=file)
        window = (video_start / fps, (video_start + length) / fps)
        frames = video.decode_window(path, *window, fps)
        if len(frames) != length:
            raise CorruptDatasetError(f"the video {key} of episode {index} has {len(frames)} frames")
        stats[key] = st.image_stats(frames)
        digests[digest.video_column(key)] = video.packet_digests(path, [window], fps)[0]
    for key in STANDARD_COLUMNS:
        stats[key] = st.vector_stats(table.column(key).to_numpy())
    extras_path = root / layout.EXTRAS_PATH.format(episode_index=index)
    extras = load_json(extras_path) if extras_path.exists() else None
    for column, path in ((digest.EXTRAS, extras_path), (digest.STATES, root / layout.ARRAYS_PATH.format(
            episode_index=index))):
        if path.is_file():
            digests[column] = digest.of_file(path)
    start = int(before["dataset_to_index"]) if before is not None else 0
    return episode_row(index, tasks[task_index], length, start, position=position, video_start=video_start,
                       chunks_size=chunks_size, fps=fps, cameras=cameras, stats=stats,
                       extras=extras if isinstance(extras, dict) else None, digests=digests)


def _files_of(scan: Scan, episodes: range) -> set[str]:
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

