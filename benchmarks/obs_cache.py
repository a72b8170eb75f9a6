"""A directory of pickled results that the critic benchmarks keep between runs.

A rollout's observations do not depend on the critic that judges them, so a benchmark that stores
them re-judges a changed critic in seconds. They do depend on everything else (the oracle's labels,
the skills, the physics, the renderer), so a directory is stamped with a fingerprint of the package
outside ``vcage/critics`` (and the layers above the pipeline, ``policy`` and ``cli``, which the
rollouts cannot import) when first filled, and refused by code with another fingerprint: stale
rollouts never pass for fresh ones. Each entry is written to a temporary file and renamed into
place: a run stopped or failing mid-write leaves no truncated entry for the next run to trip on.
"""

from __future__ import annotations

import gzip
import hashlib
import os
import pickle
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

import vcage

T = TypeVar("T")
STAMP = "SOURCE"  # the file in a cache directory that holds its fingerprint


class StaleCache(SystemExit):
    """The cache directory was filled by other code than this checkout's."""


NOT_ROLLOUTS = ("critics", "policy", "cli")  # what a stored rollout cannot depend on (import layers)


def fingerprint(root: Path | None = None) -> str:
    """A digest of the package's files outside :data:`NOT_ROLLOUTS` (what a stored rollout depends
    on: the pipeline and the stages below it; the layers contract keeps ``policy`` and ``cli`` out)."""
    root = Path(vcage.__file__).parent if root is None else root
    digest = hashlib.sha256()
    for path in sorted(p for p in root.rglob("*") if p.is_file()):
        rel = path.relative_to(root)
        if rel.parts[0] in NOT_ROLLOUTS or "__pycache__" in rel.parts:
            continue
        digest.update(str(rel).encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()[:16]


def open_cache(directory: str | None, source: str | None = None) -> Path | None:
    """``directory``, created and stamped with ``source`` (default: this checkout's
    :func:`fingerprint`) if new; :class:`StaleCache` if it holds entries of other code."""
    if directory is None:
        return None
    path, source = Path(directory), source or fingerprint()
    path.mkdir(parents=True, exist_ok=True)
    stamp = path / STAMP
    if stamp.is_file():
        if stamp.read_text().strip() != source:
            raise StaleCache(f"{path} holds rollouts made by other code than this checkout's (it changed "
                             "outside vcage/critics since, or the benchmark's entries changed form): give "
                             "--cache a fresh directory")
    elif any(path.iterdir()):
        raise StaleCache(f"{path} holds files but no {STAMP} stamp saying which code made them: give "
                         "--cache a fresh directory")
    else:
        stamp.write_text(source + "\n")
    return path


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
