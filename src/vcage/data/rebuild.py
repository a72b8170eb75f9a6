"""Metadata rows rebuilt from the episodes' own files, for the committed episodes of a vcage dataset
whose ``meta/episodes`` row a damaged file lost."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pyarrow.compute as pc

from vcage.data import digest, layout, video
from vcage.data import stats as st
from vcage.data.files import episode_row
from vcage.data.reader import NPZ_ERRORS, STANDARD_COLUMNS, column_to_numpy, load_json, read_parquet
from vcage.data.scan import Scan
from vcage.errors import CorruptDatasetError, DatasetError


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
