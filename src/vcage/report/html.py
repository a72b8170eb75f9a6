"""The page itself: the report's Jinja2 template (package data) rendered with autoescaping."""

from __future__ import annotations

from collections.abc import Sequence

from jinja2 import Environment, PackageLoader, StrictUndefined

from vcage.report.page import DatasetPage

TEMPLATE = "report.html.j2"


def environment() -> Environment:
    env = Environment(loader=PackageLoader("vcage.report", "templates"), autoescape=True,
                      undefined=StrictUndefined, trim_blocks=True, lstrip_blocks=True,
                      keep_trailing_newline=True)
    env.filters["pct"] = lambda x: f"{100 * x:.1f}%"
    env.filters["secs"] = lambda x: f"{x:,.1f} s"
    env.filters["rate"] = lambda x: f"{x:,.0f}"
    return env


def render(pages: Sequence[DatasetPage], version: str) -> str:
    """The HTML of a report on ``pages`` (one dataset, or two side by side)."""
    return environment().get_template(TEMPLATE).render(pages=list(pages), version=version)
