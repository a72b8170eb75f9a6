"""Repair that keeps every intact episode: the damaged ones go, the rest are renumbered.

LeRobot's episode indices must be contiguous, so dropping episode k of n moves every episode after
it down by one. Nothing an intact episode holds changes but its index: its data rows are copied
with ``episode_index``, ``index`` and ``task_index`` renumbered (every value column byte for byte),
its videos by copying their encoded packets (:func:`vcage.data.video.concat_videos`, so its packet
digests hold), its extras and states files byte for byte under their new names. An episode whose
only damage is in its videos can be rendered again from its stored simulator states when a
``render`` function is given; it is kept only if the encoded packets come out identical to those
its row recorded (the same renderer and encoder on the same states), else it is dropped.

Crash safety: the new files are built in ``.repair-staging/`` inside the dataset (a crash there
leaves the dataset as it was; the next repair deletes the folder). Then ``PLAN.json`` is written:
from that moment the repair is carried through by whoever finds it (:func:`finish`): the replaced
files move into the quarantine folder, then the new ones move in, ``meta/info.json`` (the commit
point) last. Until then ``vcage verify`` reports an interrupted repair, and every writer refuses
the dataset.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from vcage.data import digest, layout, video
from vcage.data import stats as st
from vcage.data.card import dataset_card
from vcage.data.files import (
    atomic_write,
    episode_row,
    episodes_table,
    remove_empty_dirs,
    tasks_table,
    write_json,
    write_table,
    write_text,
)
from vcage.data.reader import NPZ_ERRORS, load_json, load_npz, read_parquet
from vcage.data.scan import Scan
from vcage.data.verify_report import VerifyReport, span
from vcage.errors import DatasetError

# (an episode's extras, its stored simulator states) -> the frames of each camera, by feature key
Render = Callable[[dict[str, Any], np.ndarray], dict[str, np.ndarray]]

ASIDE_DONE = "ASIDE-DONE"  # written once every replaced file is in the quarantine


@dataclass(frozen=True)
class Compaction:
    """What :func:`compact` did. Episode numbers are the old ones unless said otherwise."""

    kept: int  # episodes the dataset holds now
    dropped: tuple[int, ...]
    renumbered: dict[int, int]  # old index -> new index, for the kept episodes that moved
    rerendered: tuple[int, ...]  # kept after their videos were rendered again from their states
    reasons: dict[int, list[str]]  # dropped episode -> why
    aside: tuple[str, ...]  # files moved into the quarantine
    put: tuple[str, ...]  # files written


def kept_tasks(tasks: list[str] | None, rows: list[dict[str, Any]]) -> list[str]:
    """The task list for the kept rows: a prefix of the existing list up to the last task they use
    (task indices in the data files stay valid), or, when ``tasks.parquet`` is lost, the tasks in
    order of first appearance (the order the writer gives them)."""
    used = [str((r.get("tasks") or [""])[0]) for r in rows]
    if tasks is not None and all(t in tasks for t in used):
        return tasks[:1 + max((tasks.index(t) for t in used), default=-1)]
    return list(dict.fromkeys(used))


def info_for(static: dict[str, Any], rows: list[dict[str, Any]], tasks: list[str]) -> dict[str, Any]:
    """``meta/info.json`` for a dataset that holds ``rows`` (episodes 0..n-1) and ``tasks``."""
    return {**static, "total_episodes": len(rows), "total_frames": sum(int(r["length"]) for r in rows),
            "total_tasks": len(tasks) if rows else 0, "splits": {"train": f"0:{len(rows)}"}}


def stats_for(rows: list[dict[str, Any]]) -> dict[str, st.Stats]:
    """The dataset's statistics: the per-episode statistics of ``rows`` merged."""
    stats: dict[str, st.Stats] = {}
    for row in rows:
        stats = st.merge(stats, st.from_row(row))
    return stats


def compact(scan: Scan, found: VerifyReport, quarantine: str, render: Render | None = None) -> Compaction:
    """Drop the episodes ``found`` names as damaged (and those whose row is lost), keep every other
    one renumbered, and commit that crash-safely; see the module docstring.

    ``quarantine`` is the folder (relative to the dataset) that receives the replaced files.
    """
    root, static = scan.root, scan.static
    assert static is not None and found.damaged
    staging = root / layout.REPAIR_STAGING
    if staging.exists():
        shutil.rmtree(staging)
    staging.mkdir()
    fps, chunks_size = int(static["fps"]), int(static.get("chunks_size") or layout.CHUNKS_SIZE)
    cameras = [k for k, f in static["features"].items() if f.get("dtype") == "video"]
    reasons: dict[int, list[str]] = {}
    for p in found.problems:
        for i in p.episodes:
            reasons.setdefault(i, []).append(f"{p.path}: {p.what}")
    for i in range(scan.episodes):
        if i not in scan.rows:
            reasons.setdefault(i, []).append("its metadata row is lost and could not be rebuilt")
    rendered = _render_again(scan, reasons, staging / ".render", cameras, render)
    damaged = sorted(i for i in reasons if i not in rendered)
    first = min(reasons)
    p0 = _first_position(scan, first)
    kept = [i for i in range(scan.episodes) if i not in damaged]
    moved = [i for i in kept if i >= first or layout.row_position(scan.rows[i], "data") >= p0]
    untouched = [i for i in kept if i not in moved]
    new_index = {i: n for n, i in enumerate(kept)}
    tasks = kept_tasks(scan.tasks, [scan.rows[i] for i in kept])
    features = static["features"]

    rows = [scan.rows[i] for i in untouched]
    start = int(rows[-1]["dataset_to_index"]) if rows else 0
    position: tuple[int, int] | None = None
    groups: list[list[int]] = []
    for i in moved:  # episodes that shared a file stay together in one new file
        if groups and layout.row_position(scan.rows[groups[-1][-1]], "data") == \
                layout.row_position(scan.rows[i], "data"):
            groups[-1].append(i)
        else:
            groups.append([i])
    put: list[str] = []
    for group in groups:
        position = p0 if position is None else layout.next_position(position, chunks_size)
        old = layout.row_position(scan.rows[group[0]], "data")
        source = read_parquet(root / static["data_path"].format(chunk_index=old[0], file_index=old[1]))
        tables, video_start = [], 0
        clips: dict[str, list[tuple[Path, int, int]]] = {key: [] for key in cameras}
        for i in group:
            row, j = scan.rows[i], new_index[i]
            length, task = int(row["length"]), str((row.get("tasks") or [""])[0])
            table = _renumbered(source.filter(pc.equal(source.column("episode_index"), i)),
                                j, start, tasks.index(task))
            tables.append(table)
            stats = st.from_row(row) | {c: st.vector_stats(table.column(c).to_numpy())
                                        for c in ("episode_index", "index", "task_index")}
            digests = {c: v for c, v in row.items() if c.startswith(digest.PREFIX) and isinstance(v, str)}
            digests[digest.DATA] = digest.of_rows(table.select([n for n in table.column_names
                                                                if n in features]))
            extras = _extras(root, i)
            rows.append(episode_row(j, task, length, start, position=position, video_start=video_start,
                                    chunks_size=chunks_size, fps=fps, cameras=cameras, stats=stats,
                                    extras=extras, digests=digests))
            for key in cameras:
                if i in rendered:
                    clips[key].append((rendered[i][key], 0, length))
                else:
                    at = layout.row_position(row, key)
                    path = root / static["video_path"].format(video_key=key, chunk_index=at[0],
                                                              file_index=at[1])
                    clips[key].append((path, round(float(row[f"videos/{key}/from_timestamp"]) * fps), length))
            if i >= first:  # its extras were taken out with the rest from ``first`` on
                for template in (layout.EXTRAS_PATH, layout.ARRAYS_PATH):
                    was = root / template.format(episode_index=i)
                    if was.is_file():
                        rel = template.format(episode_index=j)
                        shutil.copyfile(was, _staged(staging, rel))
                        put.append(rel)
            start += length
            video_start += length
        rel = static["data_path"].format(chunk_index=position[0], file_index=position[1])
        write_table(_staged(staging, rel), pa.concat_tables(tables))
        put.append(rel)
        for key in cameras:
            rel = static["video_path"].format(video_key=key, chunk_index=position[0], file_index=position[1])
            video.concat_videos(clips[key], _staged(staging, rel), fps)
            put.append(rel)
    put += _stage_meta(scan, staging, rows, tasks)
    aside = _replaced(scan, first, p0)
    dropped = tuple(damaged)
    note = _note(found, len(kept), dropped, {i: reasons[i] for i in dropped}, aside)
    shutil.rmtree(staging / ".render", ignore_errors=True)
    plan = {"quarantine": quarantine, "aside": aside, "put": put, "note": note}
    atomic_write(root / layout.REPAIR_PLAN, lambda tmp: tmp.write_text(json.dumps(plan, indent=1)))
    finish(root)
    return Compaction(len(kept), dropped, {i: n for i, n in new_index.items() if n != i},
                      tuple(sorted(rendered)), {i: reasons[i] for i in dropped}, tuple(aside), tuple(put))


def finish(root: Path) -> bool:
    """Carry an interrupted repair through, or forget one that never reached its plan; whether a
    repair was carried through. Idempotent: a crash inside it is finished by the next call."""
    staging = root / layout.REPAIR_STAGING
    if not staging.is_dir():
        return False
    if not (root / layout.REPAIR_PLAN).is_file():  # the crash came while staging: the dataset is as it was
        shutil.rmtree(staging)
        return False
    plan = json.loads((root / layout.REPAIR_PLAN).read_text())
    quarantine = root / plan["quarantine"]
    if not (staging / ASIDE_DONE).exists():
        for rel in plan["aside"]:
            src, dst = root / rel, quarantine / rel
            if src.is_file() and not dst.exists():
                dst.parent.mkdir(parents=True, exist_ok=True)
                os.replace(src, dst)
        quarantine.mkdir(parents=True, exist_ok=True)
        write_text(quarantine / "NOTE.md", plan["note"])
        write_text(staging / ASIDE_DONE, "")
    puts = sorted(plan["put"], key=lambda rel: rel == layout.INFO_PATH)  # the commit point last
    for rel in puts:
        if (staging / rel).is_file():
            (root / rel).parent.mkdir(parents=True, exist_ok=True)
            os.replace(staging / rel, root / rel)
    shutil.rmtree(staging)
    for sub in ("data", "videos", "extras", "meta/episodes"):
        if (root / sub).is_dir():
            with contextlib.suppress(OSError):
                remove_empty_dirs(root / sub, keep_root=True)
    return True


def _staged(staging: Path, rel: str) -> Path:
    path = staging / rel
    path.parent.mkdir(parents=True, exist_ok=True)
    return path


def _first_position(scan: Scan, first: int) -> tuple[int, int]:
    """The first data/video position the repair rewrites: that of the first damaged episode (the
    episodes before it in the same file move with the rest), or of the episode before it where its
    row is lost."""
    for i in (first, first - 1):
        if i >= 0 and i in scan.rows:
            with contextlib.suppress(KeyError, ValueError, TypeError):
                return layout.row_position(scan.rows[i], "data")
    return (0, 0)


def _renumbered(table: pa.Table, episode: int, start: int, task: int) -> pa.Table:
    """The rows of one episode with its new episode index, dataset indices from ``start`` and task
    index; the other columns untouched."""
    n = table.num_rows
    for name, values in (("episode_index", np.full(n, episode)), ("index", np.arange(start, start + n)),
                         ("task_index", np.full(n, task))):
        at = table.schema.get_field_index(name)
        field = table.schema.field(at)
        table = table.set_column(at, field, pa.array(values, type=field.type))
    return table


def _extras(root: Path, index: int) -> dict[str, Any] | None:
    path = root / layout.EXTRAS_PATH.format(episode_index=index)
    if not path.is_file():
        return None
    extras = load_json(path)
    return extras if isinstance(extras, dict) else None


def _render_again(scan: Scan, reasons: dict[int, list[str]], scratch_dir: Path, cameras: list[str],
                  render: Render | None) -> dict[int, dict[str, Path]]:
    """The episodes whose only damage is in their videos and whose videos, rendered again from their
    stored states and encoded, give exactly the packets their rows recorded: episode -> camera ->
    a one-episode video. A try that does not reproduce them adds its reason to ``reasons``."""
    if render is None or not cameras:
        return {}
    static = scan.static
    assert static is not None
    fps = int(static["fps"])
    encoder = video.encoder_for({static["features"][k]["info"]["video.codec"] for k in cameras})
    out: dict[int, dict[str, Path]] = {}
    for i in sorted(reasons):
        row = scan.rows.get(i)
        paths = [r.split(": ", 1)[0] for r in reasons[i]]
        kinds = {(layout.file_position(p) or ("?", None))[0] for p in paths}
        if row is None or not kinds <= set(cameras):
            continue
        try:
            extras = _extras(scan.root, i)
            states = load_npz(scan.root / layout.ARRAYS_PATH.format(episode_index=i)).get("states")
            if extras is None or states is None:
                continue
            frames = render(extras, states)
            clips = {}
            for key in cameras:
                recorded = row.get(digest.video_column(key))
                if len(frames[key]) != int(row["length"]) or not isinstance(recorded, str):
                    raise DatasetError("the states give another number of frames")
                path = _staged(scratch_dir, f"{i}/{key}.mp4")
                video.encode_video(path, frames[key], fps=fps, encoder=encoder)
                if video.packet_digests(path, [(0.0, len(frames[key]) / fps)], fps)[0] != recorded:
                    raise DatasetError("its videos rendered again from its states differ from those written "
                                       "(another renderer or encoder?)")
                clips[key] = path
        except (DatasetError, KeyError, ValueError, TypeError, *NPZ_ERRORS) as exc:
            reasons[i].append(f"not rendered again: {exc}")
            continue
        out[i] = clips
    return out


def _stage_meta(scan: Scan, staging: Path, rows: list[dict[str, Any]], tasks: list[str]) -> list[str]:
    """``info.json``, ``stats.json``, ``tasks.parquet``, the episodes files and the card for ``rows``."""
    static = scan.static
    assert static is not None
    info = info_for(static, rows, tasks)
    write_json(_staged(staging, layout.INFO_PATH), info)
    put = [layout.INFO_PATH]
    if rows:
        write_json(_staged(staging, layout.STATS_PATH), st.to_json(stats_for(rows)))
        write_table(_staged(staging, layout.TASKS_PATH), tasks_table(tasks))
        put += [layout.STATS_PATH, layout.TASKS_PATH]
        by_chunk: dict[int, list[dict[str, Any]]] = {}
        for row in rows:
            by_chunk.setdefault(int(row["meta/episodes/chunk_index"]), []).append(row)
        for chunk, chunk_rows in sorted(by_chunk.items()):
            rel = layout.EPISODES_PATH.format(chunk_index=chunk, file_index=0)
            write_table(_staged(staging, rel), episodes_table(chunk_rows))
            put.append(rel)
    if scan.marker is not None:
        write_text(_staged(staging, layout.CARD_PATH), dataset_card(info, tasks if rows else []))
        put.append(layout.CARD_PATH)
    return put


def _replaced(scan: Scan, first: int, p0: tuple[int, int]) -> list[str]:
    """The files the repair takes out of the dataset (into the quarantine): the data and video files
    from ``p0`` on, the extras of the episodes from ``first`` on, and the metadata it rewrites."""
    root = scan.root
    out = []
    for path in sorted(root.rglob("*")):
        if not path.is_file() or path.is_relative_to(root / layout.REPAIR_STAGING):
            continue
        rel = path.relative_to(root).as_posix()
        position, index = layout.file_position(rel), layout.extras_episode(rel)
        if (position is not None and position[1] >= p0) or (index is not None and index >= first) \
                or rel.startswith("meta/episodes/") \
                or rel in (layout.INFO_PATH, layout.STATS_PATH, layout.TASKS_PATH, layout.CARD_PATH):
            out.append(rel)
    return out


def _note(found: VerifyReport, kept: int, dropped: tuple[int, ...], reasons: dict[int, list[str]],
          aside: list[str]) -> str:
    lines = [f"# Set aside by `vcage verify --repair` on {time.strftime('%Y-%m-%d %H:%M:%S')}", "",
             f"The dataset keeps {kept} episodes (renumbered 0..{kept - 1}); it dropped "
             + (", ".join(span(i, i) for i in dropped) if dropped else "none") + " (old numbers).", "",
             "What verify found:", "", *(f"- {p}" for p in found.problems), "",
             "Why each episode was dropped:", "",
             *(f"- episode {i}: {why}" for i, whys in reasons.items() for why in whys), "",
             "The files here are the dataset's files as they were before the repair (old episode "
             "numbers); the repair rewrote or renumbered them:", "", *(f"- {rel}" for rel in aside), ""]
    return "\n".join(lines)
