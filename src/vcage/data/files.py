"""Atomic file writes (temporary name + ``os.replace``) and JSON helpers for the dataset writer."""

from __future__ import annotations

import json
import os
import uuid
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

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


