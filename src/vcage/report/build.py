"""``vcage report``: one self-contained HTML file on a dataset, or on two side by side."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

from vcage.data.files import atomic_write, check_writable
from vcage.errors import ConfigError
from vcage.report.dataset import open_dataset
from vcage.report.html import render
from vcage.report.page import DatasetPage, Limits, dataset_page


@dataclass(frozen=True)
class ReportFile:
    path: Path
    size: int  # bytes
    pages: tuple[DatasetPage, ...]


def build_report(datasets: Sequence[Path | str], out: Path | str, limits: Limits = Limits()) -> ReportFile:
    """Write the report on ``datasets`` (one, or two to compare) to the HTML file ``out``.

    Every dataset is checked and read before anything is written; images are embedded, so the file
    is all there is to the report.
    """
    out = Path(out)
    if not 1 <= len(datasets) <= 2:
        raise ConfigError(f"a report covers one dataset or compares two; got {len(datasets)}")
    if out.is_dir():
        raise ConfigError(f"{out} is a directory; give --out a file name such as report.html")
    if limits.episodes < 0 or limits.views < 0:
        raise ConfigError(f"limits must be >= 0, got {limits}")
    check_writable(out)  # before the report is built, which takes a while
    evidence = [open_dataset(root) for root in datasets]  # all checked before any page is drawn
    labels = ["A", "B"] if len(evidence) == 2 else [""]
    pages = tuple(dataset_page(e, key, label, limits)
                  for e, key, label in zip(evidence, ("a", "b"), labels, strict=False))
    text = render(pages, _version())
    atomic_write(out, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    return ReportFile(out, len(text.encode("utf-8")), pages)


def _version() -> str:
    try:
        return version("vcage")
    except PackageNotFoundError:
        return "unknown"
