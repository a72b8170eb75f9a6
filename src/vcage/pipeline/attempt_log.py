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
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from vcage.data.files import atomic_write
from vcage.errors import DatasetError
from vcage.pipeline.stage import Stage

Record = dict[str, Any]


def read(path: Path) -> list[Record]:
    """The records of the log at ``path`` ([] if absent); a torn last line is ignored."""
    if not path.is_file():
        return []
    lines = path.read_text().splitlines()
    records = []
    for n, line in enumerate(lines, 1):
        try:
            records.append(json.loads(line))
        except json.JSONDecodeError:
            if n == len(lines):  # a crash while appending: the line was never complete
                break
            raise DatasetError(f"{path} line {n} is not JSON; the attempt log is corrupt") from None
    return records


@dataclass(frozen=True)
class Reconciled:
    records: list[Record]
    restored: int  # lines of committed episodes that were missing and are now appended
    dropped: int  # lines of episodes the dataset does not hold, removed

    @property
    def next_sample(self) -> int:
        """The first sample index no attempt has used: where the next run continues."""
        return 1 + max((int(r["episode"]) for r in self.records), default=-1)


def reconcile(path: Path, committed: Iterable[dict[str, Any]]) -> Reconciled:
    """Make the log at ``path`` match the committed episodes' extras ``committed``; rewrite it
    atomically if anything changed."""
    records = read(path)
    raw = path.read_text() if path.is_file() else ""
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
    return Reconciled(kept, len(restored), len(records) - (len(kept) - len(restored)))


def append(path: Path, records: Iterable[Record]) -> None:
    with path.open("a") as f:
        for record in records:
            f.write(json.dumps(record) + "\n")
