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
import re
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from vcage.data.files import atomic_write
from vcage.data.layout import ATTEMPTS_LOG
from vcage.data.reader import DatasetReader
from vcage.errors import CorruptDatasetError
from vcage.pipeline.stage import Stage

Record = dict[str, Any]


def rejection_group(record: Record) -> str:
    """What a rejected attempt counts under in a funnel: the first of its critic's reason codes (the
    cause of its first failed check, e.g. ``pressed.too_shallow``); without codes (a skill or scene
    failure, a critic that gives none, a log written before codes were), its reason's first clause
    with numbers replaced by ``N``."""
    codes = record.get("codes")
    if codes:
        return str(codes[0])
    return re.sub(r"\d+(\.\d+)?", "N", str(record.get("reason", "")).split(";")[0]).strip()[:90]


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
            raise CorruptDatasetError(f"{path} line {n} is not JSON; the log is corrupt (a crash tears only "
                                      "the last line)") from None
    return records


def reconcile(path: Path, committed: Iterable[dict[str, Any]]) -> int:
    """Make the log at ``path`` match the committed episodes' extras ``committed`` (rewritten
    atomically if anything changed); returns the first sample index no attempt has used, where the
    next run continues."""
    raw = path.read_text() if path.is_file() else ""
    kept = reconciled(_parse(path, raw, torn_tail=True), committed)
    text = "".join(json.dumps(r) + "\n" for r in kept)
    if text != raw:
        atomic_write(path, lambda tmp: tmp.write_text(text))
    return 1 + max((int(r["episode"]) for r in kept), default=-1)


def reconciled(records: list[Record], committed: Iterable[dict[str, Any]]) -> list[Record]:
    """``records`` as the committed episodes' extras ``committed`` hold them: the lines of a sample
    whose accepted attempt the dataset does not hold (dropped by a repair, or a log edited by hand)
    are left out, and the lines of committed episodes the log lacks are added from their extras."""
    committed = [e for e in committed if "seed" in e]  # episodes written by `vcage generate`
    held = {int(e["seed"]) for e in committed}
    orphans = {int(r["episode"]) for r in records
               if r["stage"] == Stage.ACCEPTED and int(r["seed"]) not in held}
    kept = [r for r in records if int(r["episode"]) not in orphans]
    logged = {int(r["seed"]) for r in kept if r["stage"] == Stage.ACCEPTED}
    return kept + [r for e in committed if int(e["seed"]) not in logged for r in e.get("attempts", [])]


def committed_records(root: Path) -> list[Record]:
    """The attempt log of the dataset at ``root`` as its committed episodes hold it (what
    :func:`reconcile` would leave, without writing): what ``vcage audit`` and ``vcage report`` count,
    so that episodes a repair dropped are not counted. DatasetError if the log is corrupt."""
    path = root / ATTEMPTS_LOG
    records = read(path, torn_tail=False)
    reader = DatasetReader(root, videos=False)
    return reconciled(records, (reader.extras(i) for i in range(reader.num_episodes)))


def reconcile_dataset(root: Path) -> bool:
    """Reconcile the attempt log of the dataset at ``root`` with its committed episodes (after a
    repair dropped some); whether the log changed. Nothing is done where there is no log."""
    path = root / ATTEMPTS_LOG
    if not path.is_file():
        return False
    before = path.read_bytes()
    reader = DatasetReader(root, videos=False)
    reconcile(path, [reader.extras(i) for i in range(reader.num_episodes)])
    return path.read_bytes() != before


def append(path: Path, records: Iterable[Record]) -> None:
    with path.open("a") as f:
        for record in records:
            f.write(json.dumps(record) + "\n")
