"""The version of what vcage writes into a dataset beyond LeRobot's layout, in ``meta/vcage.json``.

Each version says what a reader may expect of the files. A dataset keeps the version it was created
with (rows appended by a newer vcage add what they add; nothing is rewritten). One place for the
history and for what each version implies:

1. Before content digests: episode rows hold none (``meta/vcage.json`` has no ``schema`` key).
2. Every episode row holds the content digests of its files (``vcage/sha256/*``,
   :mod:`vcage.data.digest`); a row without them has lost them.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from vcage.errors import DatasetError

SCHEMA = 2  # what this vcage writes
HISTORY = {1: "episode rows without content digests",
           2: "content digests in every episode row (vcage/sha256/*)"}


def schema_of(marker: dict[str, Any] | None, path: Path | None = None) -> int:
    """The schema of a dataset whose ``meta/vcage.json`` holds ``marker`` (1 where it names none);
    DatasetError for one this vcage cannot read."""
    value = (marker or {}).get("schema", 1)
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise DatasetError(f"{path or 'meta/vcage.json'}: schema {value!r} is not a version number")
    if value > SCHEMA:
        raise DatasetError(f"{path or 'the dataset'} was written by a newer vcage (schema {value}; this one "
                           f"reads up to {SCHEMA}): upgrade vcage to read or append to it")
    return value


def expects_digests(schema: int) -> bool:
    """Whether every episode row of a dataset of ``schema`` holds content digests."""
    return schema >= 2
