"""Content digests of an episode's files, recorded in its ``meta/episodes`` row when it commits.

A flipped byte inside a shared MP4 or parquet file can leave every structure intact (the container
parses, the frames decode, the rows count right) and still change what an episode holds. So the
writer records, per episode, a SHA-256 of what it wrote: its data rows (their values, column by
column), the encoded packets of each camera's video in its time window (copied unchanged when
files are joined), its extras JSON and its states ``.npz`` (the files' bytes). :mod:`.verify`
recomputes them from the files, which catches any change of content and any missing file of an
episode that recorded one. Rows written before digests existed hold none (null), and are checked
as before.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pyarrow as pa

PREFIX = "vcage/sha256/"
DATA, EXTRAS, STATES = PREFIX + "data", PREFIX + "extras", PREFIX + "states"


def video_column(key: str) -> str:
    """The row's column holding the digest of camera ``key``'s packets."""
    return f"{PREFIX}videos/{key}"


def of_bytes(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def of_file(path: Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def of_rows(table: pa.Table) -> str:
    """A SHA-256 of ``table``'s values: each column's name, nesting (list sizes), value type and
    values in row order, the columns by name; the names of list items, which a parquet round trip
    may change, are left out."""
    digest = hashlib.sha256()
    for name in sorted(table.column_names):  # files joined or backfilled may order them otherwise
        column = table.column(name).combine_chunks()
        shape = []  # the nesting, without the names parquet may give list items
        while pa.types.is_list(column.type) or pa.types.is_fixed_size_list(column.type) \
                or pa.types.is_large_list(column.type):
            shape.append(str(getattr(column.type, "list_size", "*")))
            if not pa.types.is_fixed_size_list(column.type):
                digest.update(np.asarray(column.value_lengths()).tobytes())
            column = column.flatten()
        digest.update(f"{name}\0{'x'.join(shape)}\0{column.type}\0".encode())
        if pa.types.is_integer(column.type) or pa.types.is_floating(column.type) \
                or pa.types.is_boolean(column.type):
            values = column.to_numpy(zero_copy_only=False)
            digest.update(np.ascontiguousarray(values).tobytes())
        else:
            digest.update("\0".join(map(str, column.to_pylist())).encode())
        digest.update(b"\1")
    return digest.hexdigest()
