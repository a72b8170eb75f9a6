"""Atomic file writes (temporary name + ``os.replace``), the dataset lock, and JSON and table helpers
for the dataset writer and its repair."""

from __future__ import annotations

import fcntl
import json
import os
import uuid
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from vcage.data import stats as st
from vcage.data.layout import PROVENANCE
from vcage.errors import DatasetError

TMP_MARK = ".tmp-"  # temporary files are named .<name>.tmp-<pid>-<random>


def _fsync(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def atomic_write(path: Path, write: Callable[[Path], object]) -> None:
    """Call ``write(tmp)`` on a temporary name next to ``path``, then move it into place."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}{TMP_MARK}{os.getpid()}-{uuid.uuid4().hex[:8]}")
    try:
        write(tmp)
        _fsync(tmp)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def write_text(path: Path, text: str) -> None:
    atomic_write(path, lambda tmp: tmp.write_text(text))


def write_json(path: Path, obj: Any) -> None:
    atomic_write(path, lambda tmp: tmp.write_text(json.dumps(obj, indent=2, default=json_default)))


def write_table(path: Path, table: pa.Table) -> None:
    atomic_write(path, lambda tmp: pq.write_table(table, tmp))


def json_default(obj: Any) -> Any:
    if isinstance(obj, np.ndarray | np.generic):
        return obj.tolist()
    if isinstance(obj, tuple | set | frozenset):
        return list(obj)
    raise TypeError(f"{type(obj).__name__} is not JSON serialisable")


def to_json(obj: Any, what: str) -> Any:
    """``obj`` as plain JSON values (tuples become lists); DatasetError if it cannot be serialised."""
    try:
        return json.loads(json.dumps(obj, default=json_default))
    except (TypeError, ValueError) as exc:
        raise DatasetError(f"{what} must be JSON-serialisable: {exc}") from exc


def diff(expected: Any, found: Any, path: str = "") -> list[str]:
    """Dotted paths where two JSON values differ."""
    if isinstance(expected, dict) and isinstance(found, dict):
        out: list[str] = []
        for key in sorted(set(expected) | set(found), key=str):
            sub = f"{path}.{key}" if path else str(key)
            if key not in found:
                out.append(f"{sub}: missing in the existing dataset")
            elif key not in expected:
                out.append(f"{sub}: only in the existing dataset")
            else:
                out += diff(expected[key], found[key], sub)
        return out
    return [] if expected == found else [f"{path}: existing {found!r} != given {expected!r}"]


def tasks_table(tasks: list[str]) -> pa.Table:
    """tasks.parquet with pandas metadata so that pandas (and LeRobot) index it by the task string."""
    table = pa.table({"task_index": pa.array(range(len(tasks)), pa.int64()),
                      "task": pa.array(tasks, pa.string())})
    pandas_meta = {
        "index_columns": ["task"],
        "column_indexes": [{"name": None, "field_name": None, "pandas_type": "unicode",
                            "numpy_type": "object", "metadata": {"encoding": "UTF-8"}}],
        "columns": [{"name": "task_index", "field_name": "task_index", "pandas_type": "int64",
                     "numpy_type": "int64", "metadata": None},
                    {"name": "task", "field_name": "task", "pandas_type": "unicode", "numpy_type": "object",
                     "metadata": None}],
        "creator": {"library": "pyarrow", "version": pa.__version__},
        "pandas_version": "2.2.3",
    }
    return table.replace_schema_metadata({"pandas": json.dumps(pandas_meta)})




def lock_dir(root: Path) -> int:
    """Hold an exclusive ``flock`` on the directory ``root`` itself (no lock file); returns its fd.

    The lock lives as long as the descriptor (and dies with the process); DatasetError if another
    writer holds it. Release with ``os.close(fd)``.
    """
    fd = os.open(root, os.O_RDONLY | os.O_DIRECTORY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(fd)
        raise DatasetError(f"another writer is appending to {root}; wait for it to finish or "
                           "choose another --out directory") from None
    return fd


def remove_empty_dirs(root: Path, keep_root: bool) -> None:
    """Remove the empty directories under ``root`` (deepest first), and ``root`` too unless ``keep_root``."""
    for path in sorted((p for p in root.rglob("*") if p.is_dir()), key=lambda p: len(p.parts), reverse=True):
        if not any(path.iterdir()):
            path.rmdir()
    if not keep_root and root.is_dir() and not any(root.iterdir()):
        root.rmdir()


PROVENANCE_TYPES = {"vcage/seed": pa.int64(), "vcage/attempt": pa.int64(), "vcage/oracle_success": pa.bool_()}


def provenance(extras: dict[str, Any] | None) -> dict[str, Any]:
    """The provenance columns of an episode's row, from its extras (None where a key is absent)."""
    extras = extras or {}
    out: dict[str, Any] = {}
    for column, key in PROVENANCE.items():
        value = extras.get(key)
        if column == "vcage/oracle_success":
            out[column] = value if isinstance(value, bool) else None
        else:
            ok = isinstance(value, int) and not isinstance(value, bool) and -(2**63) <= value < 2**63
            out[column] = value if ok else None
    return out


def episode_row(index: int, task: str, length: int, start: int, *, chunks_size: int, fps: int,
                cameras: list[str], stats: dict[str, dict[str, np.ndarray]],
                extras: dict[str, Any] | None) -> dict[str, Any]:
    """The ``meta/episodes`` row of episode ``index`` as vcage lays it out (one episode per file),
    whose frames start at dataset index ``start``; ``stats`` are its per-episode statistics."""
    chunk, file = divmod(index, chunks_size)
    row: dict[str, Any] = {
        "episode_index": index, "tasks": [task], "length": length,
        "data/chunk_index": chunk, "data/file_index": file,
        "dataset_from_index": start, "dataset_to_index": start + length}
    for key in cameras:
        row |= {f"videos/{key}/chunk_index": chunk, f"videos/{key}/file_index": file,
                f"videos/{key}/from_timestamp": 0.0, f"videos/{key}/to_timestamp": length / fps}
    row |= {"meta/episodes/chunk_index": chunk, "meta/episodes/file_index": 0}
    row |= provenance(extras)
    row |= st.to_row(stats)
    return row


def episodes_table(rows: list[dict[str, Any]]) -> pa.Table:
    """The ``meta/episodes`` table of ``rows``: every row gets the provenance columns (null where
    unknown, e.g. rows of a dataset written before they existed), typed the same in every file."""
    rows = [row | {column: row.get(column) for column in PROVENANCE} for row in rows]
    table = pa.Table.from_pylist(rows)
    for column, kind in PROVENANCE_TYPES.items():
        i = table.schema.get_field_index(column)
        table = table.set_column(i, column, table.column(column).cast(kind))
    return table
