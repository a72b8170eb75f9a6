"""New per-frame features for an existing dataset, computed per episode, written crash-safely.

:func:`add_features` rewrites each data file with the new columns, then the episodes metadata (the
new features' per-episode statistics), ``meta/stats.json``, ``meta/vcage.json``'s copy of the
layout and the card, and ``meta/info.json`` last: until that commit readers see the dataset as it
was (extra columns and statistics are ignored by every reader), so a crash anywhere leaves a valid
dataset and running it again completes the job.
"""

from __future__ import annotations

import os
from collections import defaultdict
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from vcage.data import digest, layout
from vcage.data import stats as st
from vcage.data.card import dataset_card
from vcage.data.files import episodes_table, lock_dir, settle_interrupted, write_json, write_table, write_text
from vcage.data.reader import DTYPES, STANDARD_COLUMNS, DatasetReader, Feature, load_json, read_parquet
from vcage.data.verify import check
from vcage.errors import DatasetError

Values = Callable[[int], Mapping[str, np.ndarray]]  # episode index -> (T, n) array per new feature


def add_features(root: str | Path, features: Mapping[str, Feature], values: Values,
                 progress: Callable[[int, int], None] | None = None) -> int:
    """Add ``features`` to every episode of the dataset at ``root``; returns how many were added.

    ``values(i)`` gives episode ``i``'s frames of each new feature, (T, n) in frame order.
    Features the dataset already has are skipped (0 when all are there). Holds the writer's lock;
    refuses a damaged dataset (run ``vcage verify --repair`` first) and values of the wrong shape
    or non-finite ones (DatasetError naming the episode), before anything is written for them.
    ``progress(done, total)`` is called after each data file.
    """
    root = Path(root)
    fd = lock_dir(root)
    try:
        settle_interrupted(root)  # an interrupted episode's replaced files: the committed bytes
        report = check(root)
        report.raise_if_damaged()
        reader = DatasetReader(root)
        new = {k: f for k, f in features.items() if k not in reader.features}
        if not new:
            return 0
        taken = set(STANDARD_COLUMNS) | set(reader.cameras)
        if taken & set(new):
            raise DatasetError(f"feature names {sorted(taken & set(new))} clash with standard columns or "
                               "cameras; rename them")
        if reader.num_episodes == 0:
            raise DatasetError(f"{root} holds no episode to add features to")
        rows = [dict(reader.episode_meta(i)) for i in range(reader.num_episodes)]
        by_file: dict[tuple[int, int], list[int]] = defaultdict(list)
        for i, row in enumerate(rows):
            by_file[layout.row_position(row, "data")].append(i)
        stats: dict[str, st.Stats] = {}
        for done, (position, episodes) in enumerate(sorted(by_file.items())):
            path = root / reader.info["data_path"].format(chunk_index=position[0], file_index=position[1])
            table = read_parquet(path)
            order = np.repeat(episodes, [int(rows[i]["length"]) for i in episodes])
            if not np.array_equal(table.column("episode_index").to_numpy(), order):
                raise DatasetError(f"{path} does not hold the rows of episodes {episodes[0]}-{episodes[-1]} "
                                   "in order; run `vcage verify` on the dataset")
            columns: dict[str, list[np.ndarray]] = {k: [] for k in new}
            for i in episodes:
                mine = table.filter(pc.equal(table.column("episode_index"), i))
                got = _checked(values(i), new, i, mine.num_rows)
                episode_stats = {k: st.vector_stats(v) for k, v in got.items()}
                rows[i] |= st.to_row(episode_stats)
                for k, v in got.items():
                    columns[k].append(v)
            for key, feature in new.items():
                if key in table.column_names:  # left by an interrupted run: computed again
                    table = table.drop_columns([key])
                table = table.append_column(key, _column(np.concatenate(columns[key]), feature))
            for i in episodes:  # the rows' content digests cover the new columns from the commit on
                if isinstance(rows[i].get(digest.DATA), str):
                    mine = table.filter(pc.equal(table.column("episode_index"), i))
                    rows[i][digest.DATA] = digest.of_rows(mine)
            write_table(path, table)
            if progress is not None:
                progress(done + 1, len(by_file))
        for row in rows:
            stats = st.merge(stats, st.from_row(row))
        _commit(root, reader, new, rows, stats)
        return len(new)
    finally:
        os.close(fd)


def _checked(got: Mapping[str, np.ndarray], new: Mapping[str, Feature], index: int,
             length: int) -> dict[str, np.ndarray]:
    out = {}
    for key, feature in new.items():
        if key not in got:
            raise DatasetError(f"no values of {key!r} for episode {index}")
        arr = np.asarray(got[key])
        if arr.ndim == 1 and feature.shape[0] == 1:
            arr = arr[:, None]
        if arr.shape != (length, feature.shape[0]):
            raise DatasetError(f"episode {index}: {key!r} has shape {arr.shape}, the episode needs "
                               f"({length}, {feature.shape[0]})")
        if arr.dtype.kind == "f" and not np.isfinite(arr).all():
            raise DatasetError(f"episode {index}: {key!r} holds NaN or infinite values")
        out[key] = arr.astype(np.dtype(feature.dtype))
    return out


def _column(values: np.ndarray, feature: Feature) -> pa.Array:
    flat = pa.array(values.reshape(-1), DTYPES[feature.dtype])
    return flat if feature.shape[0] == 1 else pa.FixedSizeListArray.from_arrays(flat, feature.shape[0])


def _commit(root: Path, reader: DatasetReader, new: Mapping[str, Feature], rows: list[dict[str, Any]],
            stats: dict[str, st.Stats]) -> None:
    """Episodes metadata, stats, the marker's layout copy and the card, then info.json (the commit)."""
    by_meta: dict[tuple[int, int], list[dict[str, Any]]] = defaultdict(list)
    for row in rows:
        by_meta[(int(row["meta/episodes/chunk_index"]), int(row["meta/episodes/file_index"]))].append(row)
    for (chunk, file), file_rows in sorted(by_meta.items()):
        write_table(root / layout.EPISODES_PATH.format(chunk_index=chunk, file_index=file),
                    episodes_table(file_rows))
    write_json(root / layout.STATS_PATH, st.to_json(stats))
    info = dict(reader.info)
    info["features"] = {**info["features"], **{k: f.to_info() for k, f in new.items()}}
    marker_path = root / layout.VCAGE_PATH
    if marker_path.is_file():
        marker = load_json(marker_path)
        if isinstance(marker, dict) and isinstance(marker.get("info"), dict):
            marker["info"]["features"] = info["features"]
            write_json(marker_path, marker)
        write_text(root / layout.CARD_PATH, dataset_card(info, reader.tasks))
    write_json(root / layout.INFO_PATH, info)
