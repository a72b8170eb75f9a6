"""The evidence of one dataset, read once: configuration, attempt log, runs log, audit.

The dataset is checked first (``vcage verify``'s cheap checks); a damaged one is refused with the
damage named. Frames and videos are read only through :class:`~vcage.data.DatasetReader`; the logs
through the pipeline's readers.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from vcage.data import DatasetReader
from vcage.data.layout import ATTEMPTS_LOG, RUNS_LOG
from vcage.data.verify import check
from vcage.errors import CorruptDatasetError, DatasetError
from vcage.pipeline import attempt_log
from vcage.pipeline.audit import AuditReport, audit

Record = dict[str, Any]


@dataclass(frozen=True)
class RunEvidence:
    root: Path
    reader: DatasetReader
    config: dict[str, Any]  # the "generate" configuration tree of meta/vcage.json
    plan: dict[str, Any]  # the plan every episode executed
    attempts: list[Record]  # the attempt log, one record per attempt
    runs: list[Record]  # the runs log, one record per generation run
    audit: AuditReport


def open_dataset(root: Path | str) -> RunEvidence:
    """Check and read the dataset at ``root``.

    DatasetError if it is not a vcage dataset or has no attempt log; CorruptDatasetError if a
    file is damaged.
    """
    root = Path(root)
    if not root.exists():
        raise DatasetError(f"{root} does not exist; give the directory of a dataset made by `vcage generate`")
    report = check(root)  # DatasetError if this is not a dataset at all
    report.raise_if_damaged()
    reader = DatasetReader(root)
    log = root / ATTEMPTS_LOG
    if not log.is_file():
        raise DatasetError(f"{log} is missing: the report shows the attempts of a dataset made by "
                           "`vcage generate`, and this one was made otherwise or its attempt log was removed")
    try:
        attempts = attempt_log.committed_records(root)  # not the attempts of episodes a repair dropped
        runs = attempt_log.read(root / RUNS_LOG, torn_tail=False)
        report_of_audit = audit(root)
    except DatasetError as exc:
        raise CorruptDatasetError(str(exc)) from exc
    except (KeyError, TypeError, ValueError) as exc:
        raise CorruptDatasetError(f"{log} holds a record that lacks or mangles a field ({exc!r}); the "
                                  "log is corrupt") from exc
    config = reader.config or {}
    return RunEvidence(root, reader, dict(config.get("generate") or {}), dict(config.get("plan") or {}),
                       attempts, runs, report_of_audit)
