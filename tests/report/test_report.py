"""The report's numbers, what it embeds, and its refusals, on a real dataset (see conftest.py)."""

from __future__ import annotations

import io
import json
import shutil
from collections import Counter
from pathlib import Path

import pytest
from PIL import Image
from typer.testing import CliRunner

from vcage.cli import app
from vcage.cli.errors import EXIT_BAD_INPUT, EXIT_CORRUPT
from vcage.data import DatasetReader
from vcage.data.layout import ATTEMPTS_LOG, EXTRAS_PATH, RUNS_LOG
from vcage.errors import ConfigError, CorruptDatasetError, DatasetError
from vcage.pipeline import attempt_log, critic_views
from vcage.pipeline.audit import audit
from vcage.report import Limits, build_report
from vcage.report.episodes import boundaries, subtasks
from vcage.report.funnel import count
from vcage.report.page import flatten
from vcage.report.rejections import rejections

RUN = CliRunner()


def _record(sample: int, attempt: int, stage: str, reason: str = "", oracle: bool = True,
            accept: bool | None = None) -> dict:
    audit_rows = [{"subtask": 0, "skill": "press", "description": "the bell is pressed", "frames": [0, 9],
                   "oracle": {"pressed(bell)": oracle}, "oracle_success": oracle, "skill_error": None}]
    return {"episode": sample, "attempt": attempt, "seed": 7, "stage": stage, "reason": reason,
            "oracle_success": oracle and stage == "accepted",
            "audit": audit_rows if stage in ("critic", "accepted") else [],
            "verdicts": [{"accept": accept, "reason": "r"}] if accept is not None else []}


def test_funnel_counts_stages_reasons_and_given_up_episodes() -> None:
    records = [_record(0, 0, "accepted", accept=True),
               _record(1, 0, "critic", "subtask 1: not pressed; 3 px", accept=False),
               _record(1, 1, "critic", "subtask 1: not pressed; 5 px", accept=False),
               _record(2, 0, "placement", "no room for 2 objects"),
               _record(2, 1, "accepted", accept=True)]
    funnel = count(records)
    assert (funnel.attempts, funnel.accepted, funnel.rejected) == (5, 2, 3)
    assert (funnel.samples, funnel.given_up) == (3, 1)
    assert funnel.stages == {"placement": 1, "scene": 0, "skill": 0, "physics": 0, "critic": 2, "accepted": 2}
    assert [(r.stage, r.reason, r.attempts) for r in funnel.reasons] == [
        ("critic", "subtask N: not pressed", 2), ("placement", "no room for N objects", 1)]


def test_funnel_counts_coded_rejections_by_their_first_code_and_others_by_text() -> None:
    coded = [_record(1, 0, "critic", "subtask 1: pressed(bell): the hand stopped 3.1 mm short", accept=False),
             _record(1, 1, "critic", "subtask 2: pressed(bell): the hand stopped 1.2 mm short", accept=False),
             _record(2, 0, "critic", "subtask 1: on(a, b): only 3% of a overlaps b; released(a): ...",
                     accept=False)]
    for rec, codes in zip(coded, (["pressed.too_shallow"], ["pressed.too_shallow"],
                                  ["on.not_over_target", "released.still_touching"]), strict=True):
        rec["codes"] = codes
    funnel = count([*coded, _record(3, 0, "critic", "subtask 1: not pressed; 3 px", accept=False)])
    assert [(r.stage, r.reason, r.attempts) for r in funnel.reasons] == [
        ("critic", "pressed.too_shallow", 2), ("critic", "on.not_over_target", 1),
        ("critic", "subtask N: not pressed", 1)]


def test_rejections_put_disagreements_first_and_pair_verdict_with_oracle() -> None:
    records = [_record(0, 0, "placement", "no room"),
               _record(0, 1, "critic", "subtask 1: wrong", oracle=False, accept=False),  # agrees
               _record(0, 2, "critic", "subtask 1: wrong", oracle=True, accept=False),  # a false reject
               _record(1, 0, "accepted", accept=True)]
    found = rejections(records)
    assert [(r.sample, r.attempt) for r in found] == [(0, 2), (0, 0), (0, 1)]
    first = found[0]
    assert first.disagrees and first.critic_accept is False and first.oracle_success is True
    assert first.oracle == {"pressed(bell)": True} and first.description == "the bell is pressed"
    assert found[1].subtask is None and found[1].critic_accept is None and not found[1].disagrees


def test_keyframes_sit_at_the_start_and_the_last_frame_of_every_subtask() -> None:
    subs = subtasks({"subtasks": [{"index": i, "description": d, "frames": f, "verdict": {"accept": True}}
                                  for i, (d, f) in enumerate([("a", [0, 10]), ("b", [10, 25])])],
                     "oracle_audit": [{"subtask": 0, "oracle": {"on(a)": False}, "oracle_success": False}]})
    assert boundaries(subs, 30) == [("start", 0), ("after subtask 1", 9), ("after subtask 2", 24)]
    assert boundaries(subs, 20) == [("start", 0), ("after subtask 1", 9), ("after subtask 2", 19)]
    assert subs[0].disagrees and subs[0].oracle == {"on(a)": False} and not subs[1].oracle


def test_config_is_flattened_to_dotted_keys() -> None:
    tree = {"seed": 0, "critic": {"name": "image", "backend": None}, "render": {"size": [64, 64],
                                                                              "cameras": ["front"]}}
    assert dict(flatten(tree)) == {"seed": "0", "critic.name": "image", "critic.backend": "none",
                                   "render.size": "64 x 64", "render.cameras": "front"}


def test_pipeline_keeps_what_the_critic_saw_of_each_rejection(dataset: Path) -> None:
    rejected = [r for r in attempt_log.read(dataset / ATTEMPTS_LOG) if r["stage"] == "critic"]
    assert len(rejected) == 2
    for rec in rejected:
        png = critic_views.load(dataset, rec["episode"], rec["attempt"])
        assert png is not None
        image = Image.open(io.BytesIO(png))
        # before, during and after the press (rows) from the top and front cameras (columns), half size
        assert image.format == "PNG" and image.size == (2 * 160, 3 * 120)
    assert critic_views.load(dataset, 0, 0) is None  # accepted: nothing kept


def test_report_numbers_are_the_datasets(dataset: Path, tmp_path: Path) -> None:
    report = build_report([dataset], tmp_path / "r.html")
    (page,) = report.pages
    log = attempt_log.read(dataset / ATTEMPTS_LOG)
    stages = Counter(r["stage"] for r in log)
    assert {s: n for s, n in page.funnel.stages.items() if n} == stages == {"accepted": 2, "critic": 2}
    assert (page.funnel.attempts, page.funnel.given_up, page.episodes_held) == (4, 1, 2)
    runs = attempt_log.read(dataset / RUNS_LOG)
    assert page.runs_total.attempts == sum(r["attempts"] for r in runs) == page.funnel.attempts
    assert page.audit == audit(dataset)
    assert (page.audit.true_accept, page.audit.false_reject) == (2, 2)
    assert [(r.sample, r.attempt) for r in page.rejections] == [(1, 0), (1, 1)]
    for rejection in page.rejections:
        assert rejection.disagrees and (rejection.view or "").startswith("data:image/png;base64,")
    reader = DatasetReader(dataset)
    for episode in page.episodes:
        extras = reader.extras(episode.index)
        assert episode.seed == extras["seed"] and len(episode.subtasks) == 1
        assert [k.label for k in episode.keyframes] == ["start", "after subtask 1"]
        assert episode.keyframes[-1].frame == extras["subtasks"][0]["frames"][1] - 1
        assert set(episode.keyframes[0].images) == set(reader.cameras)
        assert episode.clip and episode.clip.startswith("data:image/webp;base64,")
    text = report.path.read_text()
    assert "http://" not in text and "https://" not in text  # nothing to fetch: it opens offline
    assert text.count('<tr class="rejection') == 2 and "scripted reject (call 2)" in text


def test_limits_list_everything_but_embed_less(dataset: Path, tmp_path: Path) -> None:
    (page,) = build_report([dataset], tmp_path / "r.html", Limits(episodes=1, views=0)).pages
    assert [bool(e.keyframes) for e in page.episodes] == [True, False] and page.episodes_with_media == 1
    assert len(page.rejections) == 2 and page.views_shown == 0
    assert all(r.view is None and "raise --views" in r.view_note for r in page.rejections)


def test_rejections_without_a_view_say_why(dataset: Path, tmp_path: Path) -> None:
    copy = tmp_path / "ds"
    shutil.copytree(dataset, copy)
    attempt_log.append(copy / ATTEMPTS_LOG, [_record(9, 0, "placement", "no room for the mouse")])
    critic_views.path(copy, 1, 1).unlink()
    (page,) = build_report([copy], tmp_path / "r.html").pages
    notes = {(r.sample, r.attempt): r.view_note for r in page.rejections}
    assert "not by the critic" in notes[(9, 0)] and "no view stored" in notes[(1, 1)] and notes[(1, 0)] == ""
    assert page.funnel.stages["placement"] == 1 and page.funnel.given_up == 2


def test_comparison_shows_both_datasets(dataset: Path, tmp_path: Path) -> None:
    made = RUN.invoke(app, ["report", str(dataset), str(dataset), "--out", str(tmp_path / "ab.html")])
    assert made.exit_code == 0, made.output
    text = (tmp_path / "ab.html").read_text()
    assert "Comparison" in text and 'id="dataset-a"' in text and 'id="dataset-b"' in text
    assert text.count('data-funnel="attempts">4<') == 2
    with pytest.raises(ConfigError, match="one dataset or compares two"):
        build_report([dataset] * 3, tmp_path / "abc.html")


def test_missing_or_foreign_directories_are_refused(tmp_path: Path) -> None:
    missing = RUN.invoke(app, ["report", str(tmp_path / "nowhere"), "--out", str(tmp_path / "r.html")])
    assert missing.exit_code == EXIT_BAD_INPUT and "does not exist" in missing.output
    (tmp_path / "empty").mkdir()
    with pytest.raises(DatasetError, match="not a dataset"):
        build_report([tmp_path / "empty"], tmp_path / "r.html")
    assert not (tmp_path / "r.html").exists()


def test_a_dataset_without_an_attempt_log_is_refused(dataset: Path, tmp_path: Path) -> None:
    copy = tmp_path / "ds"
    shutil.copytree(dataset, copy)
    (copy / ATTEMPTS_LOG).unlink()
    result = RUN.invoke(app, ["report", str(copy), "--out", str(tmp_path / "r.html")])
    said = "".join(result.output.split())  # long paths fold anywhere
    assert result.exit_code == EXIT_BAD_INPUT and "vcage_attempts.jsonlismissing" in said
    assert not (tmp_path / "r.html").exists()


def test_a_corrupt_dataset_or_log_is_refused(dataset: Path, tmp_path: Path) -> None:
    copy = tmp_path / "ds"
    shutil.copytree(dataset, copy)
    extras = copy / EXTRAS_PATH.format(episode_index=1)
    extras.write_text(extras.read_text()[:50])  # a truncated file
    result = RUN.invoke(app, ["report", str(copy), "--out", str(tmp_path / "r.html")])
    assert result.exit_code == EXIT_CORRUPT and "--repair" in result.output
    shutil.rmtree(copy)
    shutil.copytree(dataset, copy)
    with (copy / ATTEMPTS_LOG).open("a") as f:
        f.write("{not json\n" + json.dumps(_record(5, 0, "accepted", accept=True)) + "\n")
    with pytest.raises(CorruptDatasetError, match="not JSON"):
        build_report([copy], tmp_path / "r.html")
    assert not (tmp_path / "r.html").exists()


def test_out_must_be_a_file(dataset: Path, tmp_path: Path) -> None:
    result = RUN.invoke(app, ["report", str(dataset), "--out", str(tmp_path)])
    assert result.exit_code == EXIT_BAD_INPUT and "is a directory" in result.output
