"""The HTML report of a dataset's generation: the funnel, label noise and critic-oracle agreement,
throughput, every accepted episode (keyframes, verdicts beside the oracle's predicates, a clip) and
every rejected attempt (the views the critic judged, and why), or two datasets side by side.

Reads datasets through :class:`~vcage.data.DatasetReader` and the pipeline's log readers; only
the CLI imports this package (and only this package imports Jinja2 and matplotlib).
"""

from vcage.report.build import ReportFile, build_report
from vcage.report.page import Limits

__all__ = ["Limits", "ReportFile", "build_report"]
