"""Damaged datasets through the command line: verify, inspect, audit and export fail naming the
damage (never "ok", never a traceback), and ``verify --repair`` drops the damaged tail."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from vcage.cli import app
from vcage.cli.errors import MARKER
from vcage.data import DatasetReader, DatasetWriter, Feature

RUN = CliRunner()
CAM = "observation.images.front"
FEATURES = {"observation.state": Feature("float32", (2,)), "action": Feature("float32", (2,))}
VIDEO_1 = f"videos/{CAM}/chunk-000/file-001.mp4"
STATES_1 = "extras/episode_000001_states.npz"


def text(result: object) -> str:
    """The output with rich's line wrapping undone."""
    return " ".join(str(getattr(result, "output", "")).split())


def make(root: Path, episodes: int = 3) -> None:
    """Files of a byte at most: each episode's data and video in files of their own, so that one
    truncated file damages one episode (tests/data/test_packing.py covers shared files)."""
    with DatasetWriter(root, fps=10, features=FEATURES, cameras={CAM: (16, 16)}, config={"k": 1},
                       data_files_size_in_mb=1e-6, video_files_size_in_mb=1e-6) as w:
        for i in range(episodes):
            n = 4 + i
            w.add_episode({"observation.state": np.zeros((n, 2), np.float32),
                           "action": np.ones((n, 2), np.float32)},
                          {CAM: np.full((n, 16, 16, 3), 40 * i, np.uint8)}, task="press the bell",
                          extras={"seed": i, "oracle_success": True},
                          arrays={"states": np.zeros((n, 3)), "initial_state": np.zeros(3)})
    (root / "meta/vcage_attempts.jsonl").write_text("")


@pytest.fixture(scope="module")
def pristine(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("cli-verify") / "ds"
    make(root)
    return root


@pytest.fixture()
def ds(pristine: Path, tmp_path: Path) -> Path:
    shutil.copytree(pristine, tmp_path / "ds")
    return tmp_path / "ds"


def truncate(path: Path) -> None:
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])


def failed(result: object, *names: str) -> bool:
    """A refusal: non-zero exit, one ``error:`` line, no traceback, every name in the output."""
    out = text(result)
    exc = getattr(result, "exception", None)
    return (getattr(result, "exit_code", 0) != 0 and "error:" in out and "Traceback" not in out
            and isinstance(exc, SystemExit) and all(n in out for n in names))


def test_verify_is_a_wrapped_command() -> None:
    commands = {c.name: c for c in app.registered_commands}
    assert getattr(commands["verify"].callback, MARKER, False)


def test_a_clean_dataset_passes_every_verb(ds: Path) -> None:
    for verb in ("verify", "inspect", "audit"):
        result = RUN.invoke(app, [verb, str(ds)])
        assert result.exit_code == 0, (verb, result.output)
    assert "no problems" in text(RUN.invoke(app, ["verify", str(ds)]))


def test_a_truncated_video_fails_every_verb_naming_it(ds: Path, tmp_path: Path) -> None:
    truncate(ds / VIDEO_1)
    verified = RUN.invoke(app, ["verify", str(ds)])
    assert failed(verified, VIDEO_1, "episode 1", "--repair"), verified.output
    inspected = RUN.invoke(app, ["inspect", str(ds)])
    assert failed(inspected, VIDEO_1, "damaged"), inspected.output
    audited = RUN.invoke(app, ["audit", str(ds)])
    assert failed(audited, VIDEO_1), audited.output
    exported = RUN.invoke(app, ["export", str(ds), str(tmp_path / "demos.hdf5")])
    assert failed(exported, "file-001.mp4"), exported.output
    assert not (tmp_path / "demos.hdf5").exists()


def test_inspect_marks_only_the_damaged_episode(ds: Path) -> None:
    truncate(ds / STATES_1)
    result = RUN.invoke(app, ["inspect", str(ds)])
    assert failed(result, STATES_1)
    rows = {line.split("│")[1].strip(): line for line in result.output.splitlines() if line.count("│") > 6}
    assert "damaged" in rows["1"] and "damaged" not in rows["0"] and "damaged" not in rows["2"]


def test_export_of_a_truncated_states_file_is_an_error_not_a_traceback(ds: Path, tmp_path: Path) -> None:
    truncate(ds / STATES_1)
    result = RUN.invoke(app, ["export", str(ds), str(tmp_path / "demos.hdf5")])
    assert failed(result, "episode_000001_states.npz"), result.output


def test_verify_repair_drops_the_damaged_episode_then_everything_passes(ds: Path) -> None:
    truncate(ds / VIDEO_1)
    repaired = RUN.invoke(app, ["verify", str(ds), "--repair"])
    assert repaired.exit_code == 0, repaired.output
    out = text(repaired)
    assert "kept episodes 0-1, dropped 1 damaged (1)" in out and VIDEO_1 in out
    assert "2 is now 1" in out and "verified clean afterwards" in out
    assert "not rendered again" in out  # these extras hold no scene to render it from
    assert DatasetReader(ds).num_episodes == 2
    for verb in ("verify", "inspect", "audit"):
        assert RUN.invoke(app, [verb, str(ds)]).exit_code == 0, verb
    again = RUN.invoke(app, ["verify", str(ds), "--repair"])
    assert again.exit_code == 0 and "nothing to repair" in text(again)


def test_verify_of_what_is_not_a_dataset_is_bad_input(tmp_path: Path) -> None:
    result = RUN.invoke(app, ["verify", str(tmp_path / "nothing")])
    assert result.exit_code == 2 and "error:" in result.output


def _log_accepted(root: Path, episodes: int = 3) -> None:
    """The attempt log `vcage generate` writes for the episodes of :func:`make` (seed i for episode i),
    with a rejected attempt before episode 1's."""
    records = []
    for i in range(episodes):
        if i == 1:
            records.append({"episode": i, "attempt": 0, "seed": 100, "stage": "critic", "reason": "no",
                            "oracle_success": False, "audit": [], "verdicts": [], "fused_at_start": []})
        records.append({"episode": i, "attempt": int(i == 1), "seed": i, "stage": "accepted", "reason": "",
                        "oracle_success": True, "audit": [], "verdicts": [], "fused_at_start": []})
    (root / "meta/vcage_attempts.jsonl").write_text("".join(json.dumps(r) + "\n" for r in records))


@pytest.mark.parametrize(("damaged", "seeds"), [(VIDEO_1, [0, 2]),
                                                (f"videos/{CAM}/chunk-000/file-000.mp4", [1, 2])])
def test_audit_and_report_count_only_the_episodes_a_repair_kept(ds: Path, damaged: str,
                                                                 seeds: list[int]) -> None:
    """Found on 2026-12-05: after a repair dropped every episode, `vcage audit` still reported "4
    accepted episodes of 4 attempts". The audit and the report count the log as the committed
    episodes hold it, and the repair rewrites the log so."""
    _log_accepted(ds)
    assert text(RUN.invoke(app, ["audit", str(ds)])).startswith("3 accepted episodes of 4 attempts")
    truncate(ds / damaged)
    assert RUN.invoke(app, ["verify", str(ds), "--repair"]).exit_code == 0
    result = RUN.invoke(app, ["audit", str(ds)])
    assert result.exit_code == 0, result.output
    attempts = 2 + (1 in seeds)  # episode 1 took two attempts
    assert text(result).startswith(f"2 accepted episodes of {attempts} attempts"), result.output
    lines = (ds / "meta/vcage_attempts.jsonl").read_text().splitlines()
    assert [json.loads(line)["seed"] for line in lines if json.loads(line)["stage"] == "accepted"] == seeds


def test_a_corrupt_attempt_log_is_damage_to_every_command_and_repair_sets_its_lines_aside(ds: Path) -> None:
    """Found on 2026-12-05: a corrupt attempt log exited 2 in audit, 5 in report, and verify did not
    see it."""
    _log_accepted(ds)
    log = ds / "meta/vcage_attempts.jsonl"
    lines = log.read_text().splitlines(keepends=True)
    lines[1] = lines[1][: len(lines[1]) // 2] + "\n"  # a line torn in the middle of the log
    log.write_text("".join(lines))
    for verb in ("verify", "audit", "report"):
        result = RUN.invoke(app, [verb, str(ds), *(["--out", str(ds.parent / "r.html")] if verb == "report"
                                                    else [])])
        assert result.exit_code == 5 and "vcage_attempts.jsonl" in text(result), (verb, result.output)
    repaired = RUN.invoke(app, ["verify", str(ds), "--repair"])
    assert repaired.exit_code == 0, repaired.output
    [aside] = list((ds / "meta").glob("vcage_attempts.jsonl.damaged-*"))
    assert aside.read_text() == lines[1] and log.read_text() == "".join(lines[:1] + lines[2:])
    assert DatasetReader(ds).num_episodes == 3  # no episode was lost
    assert RUN.invoke(app, ["audit", str(ds)]).exit_code == 0
