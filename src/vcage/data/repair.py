"""Repair of a damaged dataset: drop the damaged episodes, keep every intact one.

In a vcage dataset the intact episodes after a damaged one are kept, renumbered so that LeRobot's
episode indices stay contiguous, and an episode whose only damage is in its videos is rendered
again from its stored states where that reproduces them exactly (:mod:`.compact`). In another
LeRobot dataset the episodes from the first damaged one to the end are dropped. The metadata that
a lost or damaged meta file held is rebuilt from the episodes' own files where it can be, and the
result is checked again. Nothing is dropped silently: the report names every dropped episode and
why, and nothing is deleted: what the repair takes out goes to ``quarantine/<time>/``.

The report is :mod:`.repair_report`'s; the repair of a damaged tail is :mod:`.truncate`'s, the
rebuilt metadata rows :mod:`.rebuild`'s, and what is set aside goes through :mod:`.quarantine`.
"""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path

from vcage.data import layout
from vcage.data.compact import Render, compact, finish
from vcage.data.files import TMP_MARK, lock_dir, settle_interrupted
from vcage.data.quarantine import Quarantine, _set_aside_bad_lines
from vcage.data.rebuild import _rebuild_rows
from vcage.data.repair_report import RepairReport
from vcage.data.scan import Scan
from vcage.data.truncate import _rewrite
from vcage.data.verify import verify
from vcage.data.verify_report import VerifyReport
from vcage.errors import CorruptDatasetError, DatasetError


def repair(root: str | Path, render: Render | None = None) -> RepairReport:
    """Drop the damaged episodes, and rewrite the metadata; never silently.

    In a vcage dataset (``meta/vcage.json``) every intact episode is kept, renumbered, by
    :func:`vcage.data.compact.compact` (crash-safe; an interrupted repair is carried through first),
    and ``render`` (an episode's extras and states -> its frames), when given, renders again the
    videos of episodes damaged in their videos alone. The rest of this docstring is the repair of
    another LeRobot dataset, and of damaged metadata alone:

    Holds the writer's lock meanwhile (DatasetError if a writer is appending). Runs :func:`verify`
    (so it costs a decode of every video, twice: before and after). The episodes before the first
    damaged one are kept: their files byte for byte, except a data or video file they share with
    dropped episodes, which is cut after the last kept episode (rows filtered, video packets copied
    without re-encoding) before anything else, so a crash there leaves the dropped episodes damaged
    and the kept ones intact. Then ``meta/info.json`` is rewritten (the commit point now counts only
    the kept episodes), then ``stats.json``, ``tasks.parquet``, the episodes files and the card,
    then the dropped episodes' files are deleted, so a crash midway leaves a dataset that reads as
    the kept episodes plus leftovers the next writer removes. Damaged metadata alone
    (``stats.json``, ``tasks.parquet``, the totals in ``info.json``, or ``info.json`` itself when
    ``meta/vcage.json`` keeps a copy of its layout) is rebuilt from the episode rows.

    Raises CorruptDatasetError if the dataset cannot be repaired this way (``meta/info.json`` lost
    with no copy, ``meta/vcage.json`` unreadable). The attempt log is not touched: reconcile it with
    ``kept``.
    """
    root = Path(root)
    if not root.is_dir():
        raise DatasetError(f"{root} is not a directory; give a dataset directory")
    fd = lock_dir(root)
    try:
        resumed = finish(root)
        before = Scan(root, decode=True).run().report()  # as a reader finds it, interrupted writes included
        restored = [p.relative_to(root).as_posix() for p in settle_interrupted(root)]  # the committed bytes
        scan = Scan(root, decode=True).run()
        if scan.report().ok:
            leftovers = _remove_scratch(root)
            after = verify(root) if restored or leftovers or resumed else before
            return RepairReport(root, before, after, after.episodes, removed=tuple(leftovers),
                                restored=tuple(restored), resumed=resumed)
        if scan.marker_damaged:
            raise CorruptDatasetError(f"cannot repair {root}: {layout.VCAGE_PATH} is damaged, and it holds "
                                      "the configuration the dataset was made with; restore it from a copy")
        if scan.static is None or not scan.count_known:
            lost = ("an episodes metadata file is damaged too, so the number of episodes is unknown"
                    if scan.static is not None else
                    f"no copy of its features is kept ({layout.VCAGE_PATH} of datasets written by older "
                    "versions has none)")
            raise CorruptDatasetError(f"cannot repair {root}: {layout.INFO_PATH} is damaged and {lost}; "
                                      "restore it from a copy")
        rebuilt = _rebuild_rows(scan)
        if rebuilt:  # an episodes file was lost: check the episodes again with their rebuilt rows
            scan = Scan(root, decode=True, rebuilt=rebuilt).run()
        found = scan.report()
        if found.damaged and scan.marker is not None:
            return _compact(scan, before, found, render, tuple(restored), resumed)
        kept = found.first_damaged if found.first_damaged is not None else found.episodes
        report = _rewrite(scan, before, found, kept, tuple(i for i in sorted(rebuilt) if i < kept))
        return replace(report, restored=tuple(restored), resumed=resumed)
    finally:
        os.close(fd)


def _compact(scan: Scan, before: VerifyReport, found: VerifyReport, render: Render | None,
             restored: tuple[str, ...], resumed: bool) -> RepairReport:
    root = scan.root
    rewritten, scratch = _set_aside_bad_lines(root), _remove_scratch(root)
    aside = Quarantine(root)
    done = compact(scan, found, aside.folder(), render)
    rebuilt = tuple(sorted(i for i in scan.rebuilt if i not in done.dropped))
    return RepairReport(root, before, verify(root), done.kept, done.dropped, (), (*rewritten, *done.put),
                        (*done.aside, *scratch), done.reasons, rebuilt, restored, aside.folder(),
                        done.renumbered, done.rerendered, resumed, compacted=True)


def _remove_scratch(root: Path) -> list[str]:
    """Delete the temporary files an interrupted write left (hidden, marked ``.tmp-``); their names."""
    out = []
    for path in sorted(root.rglob(f".*{TMP_MARK}*")):
        if path.is_file():
            path.unlink()
            out.append(path.relative_to(root).as_posix())
    return out
