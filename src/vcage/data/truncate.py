"""The repair that keeps the episodes before the first damaged one (another LeRobot dataset's, or a
dataset whose metadata alone is damaged): the files shared with dropped episodes cut, the metadata
rewritten, the dropped episodes' files set aside."""

from __future__ import annotations

import contextlib
import functools
from collections import defaultdict
from typing import Any

import pyarrow.compute as pc

from vcage.data import layout, video
from vcage.data import stats as st
from vcage.data.card import dataset_card
from vcage.data.compact import info_for, kept_tasks, stats_for
from vcage.data.files import (
    BACKUP_MARK,
    TMP_MARK,
    atomic_write,
    episodes_table,
    remove_empty_dirs,
    tasks_table,
    write_json,
    write_table,
    write_text,
)
from vcage.data.quarantine import QUARANTINE, Quarantine, _set_aside_bad_lines
from vcage.data.reader import read_parquet
from vcage.data.repair_report import RepairReport
from vcage.data.scan import Scan
from vcage.data.verify import verify
from vcage.data.verify_report import VerifyReport


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
