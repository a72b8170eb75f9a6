"""The report opened in a real browser: headless Chromium (Debian's, installed by scripts/setup.sh)
driven by Playwright. The page must load without a console error, every image must decode, and
what it shows must be the dataset's: the funnel's numbers and every rejected attempt of the log.
"""

from __future__ import annotations

import shutil
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
from typer.testing import CliRunner

from vcage.cli import app
from vcage.data.layout import ATTEMPTS_LOG, RUNS_LOG
from vcage.pipeline import attempt_log

sync_api = pytest.importorskip("playwright.sync_api", reason="the dev extra installs playwright")
CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
if not Path(CHROMIUM).is_file():
    pytest.skip("Debian's chromium is missing: scripts/setup.sh installs it (as root)",
                allow_module_level=True)


@dataclass
class Opened:
    page: sync_api.Page
    problems: list[str]  # console errors and uncaught exceptions, in order


@pytest.fixture(scope="module")
def browser() -> Iterator[sync_api.Browser]:
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, headless=True)
        yield browser
        browser.close()


def _open(browser: sync_api.Browser, html: Path) -> Opened:
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    problems: list[str] = []
    page.on("console", lambda m: m.type == "error" and problems.append(f"console.error: {m.text}"))
    page.on("pageerror", lambda exc: problems.append(f"uncaught: {exc}"))
    page.on("requestfailed", lambda r: problems.append(f"request failed: {r.url}"))
    page.goto(html.as_uri(), wait_until="load")
    page.wait_for_function("Array.from(document.images).every(i => i.complete)")
    return Opened(page, problems)


@pytest.fixture(scope="module")
def report(dataset: Path, browser: sync_api.Browser,
           tmp_path_factory: pytest.TempPathFactory) -> Iterator[Opened]:
    out = tmp_path_factory.mktemp("html") / "report.html"
    made = CliRunner().invoke(app, ["report", str(dataset), "--out", str(out)])
    assert made.exit_code == 0, made.output
    opened = _open(browser, out)
    yield opened
    opened.page.close()


def test_the_page_loads_without_errors_and_every_image_decodes(report: Opened) -> None:
    assert report.problems == []
    images = report.page.evaluate("Array.from(document.images).map("
                                  "i => ({alt: i.alt, width: i.naturalWidth, height: i.naturalHeight}))")
    # 2 charts; per episode 2 keyframes x 2 cameras and a clip; 2 rejected attempts' views
    assert len(images) == 2 + 2 * (2 * 2 + 1) + 2
    assert [i for i in images if i["width"] == 0 or i["height"] == 0] == []


def test_the_funnel_on_the_page_is_the_datasets(report: Opened, dataset: Path) -> None:
    log = attempt_log.read(dataset / ATTEMPTS_LOG)
    stages = Counter(r["stage"] for r in log)
    page = report.page
    shown = {cell.get_attribute("data-funnel-stage"): int(cell.inner_text())
             for cell in page.query_selector_all("[data-funnel-stage]")}
    assert {s: n for s, n in shown.items() if n} == stages
    assert sum(shown.values()) == len(log) == int(page.inner_text('[data-funnel="attempts"]'))
    accepted = {r["episode"] for r in log if r["stage"] == "accepted"}
    given_up = {r["episode"] for r in log} - accepted
    assert int(page.inner_text('[data-funnel="accepted"]')) == len(accepted)
    assert int(page.inner_text('[data-funnel="given_up"]')) == len(given_up) == 1
    runs = attempt_log.read(dataset / RUNS_LOG)  # what `vcage generate` printed, run by run
    assert sum((Counter(r["stages"]) for r in runs), Counter()) == stages


def test_every_rejection_in_the_log_is_listed_disagreements_first(report: Opened, dataset: Path) -> None:
    rejected = [r for r in attempt_log.read(dataset / ATTEMPTS_LOG) if r["stage"] != "accepted"]
    rows = report.page.query_selector_all("#rejections-a tr.rejection")
    listed = [(int(row.get_attribute("data-sample") or -1), int(row.get_attribute("data-attempt") or -1),
               row.get_attribute("data-stage")) for row in rows]
    assert sorted(listed) == sorted((r["episode"], r["attempt"], r["stage"]) for r in rejected)
    assert len(listed) == 2
    flags = [row.get_attribute("data-disagrees") == "true" for row in rows]
    assert flags == sorted(flags, reverse=True)  # every disagreement before every agreement
    # the oracle says every press succeeded, so each rejection by the critic is a disagreement
    assert flags == [any(bool(v["accept"]) != a["oracle_success"] for a, v in zip(r["audit"], r["verdicts"],
                                                                                   strict=True))
                     for r in rejected] == [True, True]
    for row, record in zip(rows, sorted(rejected, key=lambda r: (r["episode"], r["attempt"])), strict=True):
        assert record["reason"].split(": ", 1)[1] in row.inner_text()
        assert row.query_selector("td.view img") is not None  # what the critic saw


def test_two_datasets_side_by_side(dataset: Path, browser: sync_api.Browser, tmp_path: Path) -> None:
    out = tmp_path / "ab.html"
    made = CliRunner().invoke(app, ["report", str(dataset), str(dataset), "--out", str(out),
                                    "--episodes", "0", "--views", "0"])
    assert made.exit_code == 0, made.output
    opened = _open(browser, out)
    try:
        assert opened.problems == []
        boxes = [opened.page.locator(f"#dataset-{key}").bounding_box() for key in "ab"]
        assert boxes[0] and boxes[1] and boxes[0]["x"] < boxes[1]["x"] and boxes[0]["y"] == boxes[1]["y"]
        attempts = [int(t) for t in opened.page.locator('[data-funnel="attempts"]').all_inner_texts()]
        assert attempts == [4, 4]
    finally:
        opened.page.close()
