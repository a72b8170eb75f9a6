"""Integrity of a dataset's files (the repair that drops a damaged tail is :mod:`.repair`).

:func:`verify` checks every committed episode against the metadata that describes it: its data
parquet (readable, the expected rows, index range and frame indices), each camera's MP4 (decoded:
one frame per row within the episode's time window), its extras JSON and its states ``.npz``
(loadable, one state per frame), and the metadata itself (``meta/info.json`` totals against the
episode rows and the tasks). :func:`check` runs the cheap subset that ``vcage inspect``, ``vcage
audit``, the writer (before it appends) and the robomimic export run.

Only committed episodes are checked: files and rows beyond ``meta/info.json``'s count are a crash's
leftovers, which the writer removes when it reopens the dataset. A shared data or video file that
an interrupted episode had already replaced is checked in the backup holding its committed bytes
(:func:`vcage.data.files.committed_version`), which the next writer or repair moves back.

The pass is :class:`.scan.Scan` (its metadata part :class:`.scan_meta.MetaScan`); what it finds is
a :class:`.verify_report.VerifyReport`.
"""

from __future__ import annotations

from pathlib import Path

from vcage.data.scan import Scan
from vcage.data.verify_report import VerifyReport


def verify(root: str | Path) -> VerifyReport:
    """Check every committed episode's files and the metadata; decodes every video.

    Cost: linear in the dataset. It reads every parquet, extras and ``.npz`` file once and decodes
    every video once (without converting frames to RGB), which dominates: about as long as one
    decode of all the videos (seconds per thousand 128x128 frames on one core). Memory stays at
    one file's content. Raises DatasetError only if ``root`` is not a dataset at all; damage is
    reported, not raised (see :meth:`VerifyReport.raise_if_damaged`).
    """
    return Scan(Path(root), decode=True).run().report()


def check(root: str | Path) -> VerifyReport:
    """The cheap checks: metadata, file presence, parquet footers (row counts, columns), the arrays
    in each ``.npz`` (shapes from their headers, not decompressed), extras JSON, and each video's
    box structure and container frame count (no decoding).

    Cost: a few small reads per file; no video is decoded. Catches truncated and missing files;
    damage inside a file that leaves its structure intact needs :func:`verify`.
    """
    return Scan(Path(root), decode=False).run().report()
