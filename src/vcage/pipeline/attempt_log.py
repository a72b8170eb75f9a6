"""The attempt log, ``meta/vcage_attempts.jsonl``: every attempt of every episode, with its oracle audit.

One JSON line per attempt; ``episode`` in a record is the *sample index* ``k`` whose seeds
(:meth:`GenerateConfig.episode_seed`) the attempts used, which differs from the dataset's episode
index once an episode has been given up. An accepted episode carries its own attempts in its
extras (``attempts``) and is committed *before* its lines are appended here, so a crash between the
two loses nothing: :func:`reconcile`, run whenever a dataset is reopened for writing, appends the
lines of committed episodes the log lacks, drops the lines of accepted attempts whose episode the
dataset does not hold (a log edited by hand, or written by an older version), and drops a torn
last line. Given-up episodes exist only here.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from vcage.data.files import atomic_write
from vcage.errors import DatasetError
from vcage.pipeline.stage import Stage

Record = dict[str, Any]


def read(path: Path, torn_tail: bool = True) -> list[Record]:
    """The records of the JSON-lines file at ``path`` ([] if absent). With ``torn_tail`` a last line
    that is not JSON (a crash while appending) is ignored; any other such line is corruption."""
    return _parse(path, path.read_text() if path.is_file() else "", torn_tail)


def _parse(path: Path, text: str, torn_tail: bool) -> list[Record]:
    lines = text.splitlines()
    records = []
    for n, line in enumerate(lines, 1):
        try:
            records.append(json.loads(line))
        except json.JSONDecodeError:
            if torn_tail and n == len(lines):  # the line was never complete
                break
            raise DatasetError(f"{path} line {n} is not JSON; the log is corrupt") from None
    return records


def reconcile(path: Path, committed: Iterable[dict[str, Any]]) -> int:
    """Make the log at ``path`` match the committed episodes' extras ``committed`` (rewritten
    atomically if anything changed); returns the first sample index no attempt has used, where the
    next run continues."""
    raw = path.read_text() if path.is_file() else ""
    records = _parse(path, raw, torn_tail=True)
    committed = list(committed)
    held = {int(e["seed"]) for e in committed}
    orphans = {int(r["episode"]) for r in records
               if r["stage"] == Stage.ACCEPTED and int(r["seed"]) not in held}
    kept = [r for r in records if int(r["episode"]) not in orphans]
    logged = {int(r["seed"]) for r in kept if r["stage"] == Stage.ACCEPTED}
    restored = [r for e in committed if int(e["seed"]) not in logged for r in e.get("attempts", [])]
    kept += restored
    text = "".join(json.dumps(r) + "\n" for r in kept)
    if text != raw:
        atomic_write(path, lambda tmp: tmp.write_text(text))
    return 1 + max((int(r["episode"]) for r in kept), default=-1)


def append(path: Path, records: Iterable[Record]) -> None:
    with path.open("a") as f:
        for record in records:
            f.write(json.dumps(record) + "\n")
