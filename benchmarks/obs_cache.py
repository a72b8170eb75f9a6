"""A directory of pickled results that the critic benchmarks keep between runs.

A rollout's observations do not depend on the critic that judges them, so a benchmark that stores
them re-judges a changed critic in seconds. Each entry is written to a temporary file and renamed
into place: a run stopped or failing mid-write leaves no truncated entry for the next run to trip on.
"""

from __future__ import annotations

import gzip
import os
import pickle
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

T = TypeVar("T")


def cached(path: Path | None, make: Callable[[], T]) -> T:
    """The object stored at ``path``; where there is none (or ``path`` is None), ``make()``'s,
    stored there first."""
    if path is not None and path.is_file():
        with gzip.open(path, "rb") as f:
            return pickle.load(f)  # type: ignore[no-any-return]  # noqa: S301 - our own cache
    out = make()
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        part = path.with_name(f"{path.name}.{os.getpid()}.part")
        try:
            with gzip.open(part, "wb", compresslevel=3) as f:
                pickle.dump(out, f)
            part.replace(path)
        finally:
            part.unlink(missing_ok=True)
    return out
