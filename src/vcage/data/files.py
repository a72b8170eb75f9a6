"""Atomic file writes (temporary name + ``os.replace``), the dataset lock, and JSON and table helpers
for the dataset writer and its repair."""

from __future__ import annotations

import errno
import fcntl
import json
import os
import re
import shutil
import uuid
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from vcage.data import digest
from vcage.data import stats as st
from vcage.data.layout import INFO_PATH, PROVENANCE
from vcage.errors import ConfigError, DatasetError

TMP_MARK = ".tmp-"  # temporary files are named .<name>.tmp-<pid>-<random>
BACKUP_MARK = ".keep-"  # .<name>.keep-<n>: the file as it was with n episodes committed
_BACKUP = re.compile(r"^\.(.+)\.keep-(\d+)$")


def _fsync(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def scratch(path: Path) -> Path:
    """A temporary name next to ``path`` (hidden, marked with TMP_MARK: a crash's leftover that the
    next writer removes)."""
    return path.with_name(f".{path.name}{TMP_MARK}{os.getpid()}-{uuid.uuid4().hex[:8]}")


def atomic_write(path: Path, write: Callable[[Path], object]) -> None:
    """Call ``write(tmp)`` on a temporary name next to ``path``, then move it into place."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = scratch(path)
    try:
        write(tmp)
        _fsync(tmp)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def backup_path(path: Path, committed: int) -> Path:
    return path.with_name(f".{path.name}{BACKUP_MARK}{committed:06d}")


def keep_backup(path: Path, committed: int) -> Path:
    """Keep the bytes of ``path`` (a file that holds ``committed`` episodes' content and is about to be
    replaced by one holding another episode too) under :func:`backup_path`, so that the replacement
    can be undone if that episode never commits. A hard link where the file system allows it (no
    copy), else a copy."""
    backup = backup_path(path, committed)
    backup.unlink(missing_ok=True)
    try:
        os.link(path, backup)
    except OSError:
        tmp = scratch(backup)
        try:
            shutil.copyfile(path, tmp)
            _fsync(tmp)
            os.replace(tmp, backup)
        finally:
            tmp.unlink(missing_ok=True)
    return backup


def settle_backups(root: Path, committed: int) -> list[Path]:
    """Resolve the backups under ``root`` against the commit point: a backup taken for episode ``n``
    (it holds the file as it was before that episode) is moved back over its file when ``n`` never
    committed (``n >= committed``), else deleted. Returns the files restored."""
    restored = []
    for backup in sorted(root.rglob(f".*{BACKUP_MARK}*")):
        match = _BACKUP.match(backup.name)
        if match is None or not backup.is_file():
            continue
        original = backup.with_name(match.group(1))
        if int(match.group(2)) >= committed:
            restore_backup(backup, original)
            restored.append(original)
        else:
            backup.unlink()
    return restored


def committed_episodes(root: Path) -> int | None:
    """The episodes ``meta/info.json`` commits (its ``total_episodes``), or None where it cannot be
    read (the integrity checks report that)."""
    try:
        return int(json.loads((root / INFO_PATH).read_text())["total_episodes"])
    except (OSError, ValueError, KeyError, TypeError):
        return None


def settle_interrupted(root: Path) -> list[Path]:
    """:func:`settle_backups` against the count ``meta/info.json`` commits; nothing when it cannot be
    read (the integrity checks report that)."""
    committed = committed_episodes(root)
    return [] if committed is None else settle_backups(root, committed)


def restore_backup(backup: Path, original: Path) -> None:
    """Put a backup's bytes back at ``original`` (atomically) and remove the backup."""
    if original.exists() and os.path.samefile(backup, original):
        backup.unlink()  # never replaced: rename() between two links of one file would do nothing
    else:
        os.replace(backup, original)


def committed_version(path: Path, committed: int) -> Path:
    """The file holding what ``path`` held at the commit point: its backup if a write of episode
    ``committed`` (which never committed) replaced it and left one, else ``path`` itself."""
    backup = backup_path(path, committed)
    return backup if backup.is_file() else path


NO_SPACE = (errno.ENOSPC, errno.EDQUOT)


def no_space(root: Path, exc: OSError, committed: int) -> DatasetError:
    """The error of a write to the dataset at ``root`` that found its device full: what was kept and
    how to continue."""
    return DatasetError(f"no space left on the device of {root} ({exc.filename or exc}): the dataset holds "
                        f"{committed} committed episodes, intact; free some space, then run the same command "
                        "with --total to continue")


def check_writable(path: Path, what: str = "--out") -> None:
    """Raise ConfigError, before any work is done, if the file ``path`` cannot be written: a file
    where a directory is needed, or a directory that refuses a new file (its missing directories
    are created)."""
    for parent in path.parents:
        if parent.exists():
            if not parent.is_dir():
                raise ConfigError(f"cannot write {path}: {parent} is a file; give {what} a path in a "
                                  "directory")
            break
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        probe = path.parent / f".{path.name}.{uuid.uuid4().hex}.probe"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        raise ConfigError(f"cannot write {path}: {exc.strerror or exc}; give {what} a path in a writable "
                          "directory") from None


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


def episode_row(index: int, task: str, length: int, start: int, *, position: tuple[int, int],
                video_start: int, chunks_size: int, fps: int, cameras: list[str],
                stats: dict[str, dict[str, np.ndarray]], extras: dict[str, Any] | None,
                digests: dict[str, str] | None = None) -> dict[str, Any]:
    """The ``meta/episodes`` row of episode ``index``, whose frames start at dataset index ``start``.

    vcage keeps an episode's data and videos at the same ``position`` (chunk, file); in each video
    file the episode follows ``video_start`` frames of the episodes before it. ``stats`` are its
    per-episode statistics; ``digests`` the content digests of its files (:mod:`vcage.data.digest`).
    """
    chunk, file = position
    row: dict[str, Any] = {
        "episode_index": index, "tasks": [task], "length": length,
        "data/chunk_index": chunk, "data/file_index": file,
        "dataset_from_index": start, "dataset_to_index": start + length}
    for key in cameras:
        row |= {f"videos/{key}/chunk_index": chunk, f"videos/{key}/file_index": file,
                f"videos/{key}/from_timestamp": video_start / fps,
                f"videos/{key}/to_timestamp": (video_start + length) / fps}
    row |= {"meta/episodes/chunk_index": index // chunks_size, "meta/episodes/file_index": 0}
    row |= provenance(extras)
    row |= digests or {}
    row |= st.to_row(stats)
    return row


def episodes_table(rows: list[dict[str, Any]]) -> pa.Table:
    """The ``meta/episodes`` table of ``rows``: every row gets the provenance columns and the digest
    columns any row has (null where unknown, e.g. rows of a dataset written before they existed),
    typed the same in every file."""
    digests = sorted({c for row in rows for c in row if c.startswith(digest.PREFIX)})
    rows = [row | {column: row.get(column) for column in (*PROVENANCE, *digests)} for row in rows]
    table = pa.Table.from_pylist(rows)
    types = PROVENANCE_TYPES | dict.fromkeys(digests, pa.string())
    for column, kind in types.items():
        i = table.schema.get_field_index(column)
        table = table.set_column(i, column, table.column(column).cast(kind))
    return table
