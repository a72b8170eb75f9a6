"""Exit codes say what happened: 0 only when the dataset holds what was asked."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

import scripted_critics  # noqa: F401  (registers reject_all)
from vcage.cli import app

RUN = CliRunner()
SMALL = ["--clutter", "0", "--size", "64", "--cameras", "front"]


def test_nothing_accepted_exits_3_and_writes_nothing(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    result = RUN.invoke(app, ["generate", "press the bell", "--episodes", "1", "--out", str(out),
                              "--critic", "reject_all", "--max-attempts", "2", *SMALL])
    assert result.exit_code == 3, result.output
    assert "only 0 of the 1 episodes" in " ".join(result.output.split())
    assert not out.exists()


def test_a_complete_run_exits_0_and_total_completes(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    args = ["generate", "press the bell", "--out", str(out), "--critic", "oracle", *SMALL]
    assert RUN.invoke(app, [*args, "--episodes", "1"]).exit_code == 0
    done = RUN.invoke(app, [*args, "--episodes", "2", "--total"])
    assert done.exit_code == 0, done.output
    assert "holds 2 episodes" in " ".join(done.output.split())


def test_bad_input_exits_2(tmp_path: Path) -> None:
    result = RUN.invoke(app, ["generate", "fly to the moon", "--out", str(tmp_path / "ds")])
    assert result.exit_code == 2 and result.output.startswith("error:")


def test_an_unreachable_critic_endpoint_exits_4_before_any_simulation(tmp_path: Path) -> None:
    import socket

    with socket.socket() as s:  # a port nothing listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    out = tmp_path / "ds"
    result = RUN.invoke(app, ["generate", "press the bell", "--episodes", "1", "--out", str(out),
                              "--critic", "vlm", "--critic-url", f"http://127.0.0.1:{port}/v1",
                              "--critic-model", "m", *SMALL])
    assert result.exit_code == 4, result.output
    assert f"127.0.0.1:{port}" in " ".join(result.output.split())
    assert not out.exists() or not any(out.iterdir())


def test_a_corrupt_dataset_exits_5_and_is_never_appended_to(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    args = ["generate", "press the bell", "--out", str(out), "--critic", "oracle", *SMALL]
    assert RUN.invoke(app, [*args, "--episodes", "1"]).exit_code == 0
    video = next((out / "videos").rglob("*.mp4"))
    video.write_bytes(video.read_bytes()[: video.stat().st_size // 2])
    verbs = (["inspect", str(out)], ["audit", str(out)], ["verify", str(out)], [*args, "--episodes", "1"])
    for verb in verbs:
        result = RUN.invoke(app, verb)
        assert result.exit_code == 5, (verb[0], result.output)
        assert "file-000.mp4" in " ".join(result.output.split()), verb[0]


def test_an_output_path_under_a_file_is_bad_input(tmp_path: Path) -> None:
    a_file = tmp_path / "notes.txt"
    a_file.write_text("mine")
    result = RUN.invoke(app, ["generate", "press the bell", "--out", str(a_file / "ds"), *SMALL])
    assert result.exit_code == 2 and result.output.startswith("error:") and "is a file" in result.output
    assert a_file.read_text() == "mine"


def _bad_inputs(tmp: Path) -> list[tuple[list[str], str]]:
    """Ordinary mistakes that ended in a traceback (exit 1) on 2026-12-05, and what the error says."""
    afile = tmp / "afile"
    afile.write_text("")
    binary = tmp / "binary.json"
    binary.write_bytes(bytes(range(256)))
    array = tmp / "array.json"
    array.write_text("[1, 2]")
    return [
        (["synthesize", "a mug on a table", "--seed", "-5", "--out", str(tmp / "s")], "--seed"),
        (["generate", "press the bell", "--seed", "-5", "--out", str(tmp / "g")], "seed must be"),
        (["synthesize", "a mug on a table", "--out", str(afile)], "is a file"),
        (["generate", "press the bell", "--config", str(binary), "--out", str(tmp / "g")],
         "cannot read the configuration"),
        (["generate", "press the bell", "--config", str(array), "--out", str(tmp / "g")],
         "holds a JSON list, not an object"),
        (["report", str(tmp / "nothing-yet"), "--out", str(afile / "report.html")], "is a file"),
        (["train", str(afile), "--out", str(tmp / "r")], "is a file, not a dataset directory"),  # was exit 5
    ]


def test_ordinary_mistakes_exit_2_with_what_to_change_not_a_traceback(tmp_path: Path) -> None:
    for args, says in _bad_inputs(tmp_path):
        result = RUN.invoke(app, args)
        out = " ".join(result.output.split())
        assert result.exit_code == 2, (args, result.output, result.exception)
        assert says in out, (args, out)
        assert "Traceback" not in out
    assert not (tmp_path / "s").exists() and not (tmp_path / "g").exists()


def test_an_outage_mid_run_says_what_the_dataset_holds_and_how_to_continue(tmp_path: Path) -> None:
    """Found on 2026-12-05: an endpoint that went away mid-run ended with exit 4 and nothing on what
    the dataset held or how to continue, and no entry in the runs log."""
    import json

    from backends.fake_openai import FakeOpenAI

    out = tmp_path / "ds"
    yes = json.dumps({"success": True, "reason": "the bell was pressed"})
    with FakeOpenAI("fake-vlm") as server:
        server.script(yes)  # the first episode's one subtask; then every request fails (500)
        result = RUN.invoke(app, ["generate", "press the bell", "--episodes", "3", "--out", str(out),
                                  "--critic", "vlm", "--critic-url", server.base_url, "--critic-model",
                                  "fake-vlm", "--votes", "1", "--critic-retries", "0", *SMALL])
    said = " ".join(result.output.split())
    assert result.exit_code == 4, result.output
    assert "holds 1 committed episodes, intact" in said and "--total --episodes 3" in said, said
    [run] = [json.loads(line) for line in (out / "meta/vcage_runs.jsonl").read_text().splitlines()]
    assert run["ended"].startswith("failed: ") and run["dataset_episodes"] == 1


def test_a_run_that_commits_nothing_does_not_claim_a_log_it_did_not_write(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    result = RUN.invoke(app, ["generate", "press the bell", "--episodes", "1", "--out", str(out),
                              "--critic", "reject_all", "--max-attempts", "1", *SMALL])
    said = " ".join(result.output.split())
    assert result.exit_code == 3 and "nothing was committed" in said and "appended" not in said, said
    assert not out.exists()


@pytest.mark.slow
def test_ctrl_c_says_what_the_dataset_holds_and_logs_the_run(tmp_path: Path) -> None:
    import json
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "ds"
    args = ["generate", "press the bell", "--episodes", "50", "--out", str(out), "--critic", "oracle", *SMALL]
    # as at a terminal, where Ctrl-C reaches the program: a suite started as a background job without
    # job control inherits SIGINT ignored, and the child would never see the signal
    run = subprocess.Popen([sys.executable, "-m", "vcage.cli", *args], stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, text=True,
                           preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and run.poll() is None:
        try:
            if json.loads((out / "meta/info.json").read_text())["total_episodes"] >= 1:
                break
        except (OSError, ValueError, KeyError):
            pass
        time.sleep(0.2)
    run.send_signal(signal.SIGINT)
    said = " ".join(run.communicate(timeout=60)[0].split())
    held = json.loads((out / "meta/info.json").read_text())["total_episodes"]
    assert run.returncode == 130, said
    assert f"interrupted: the dataset in {out}/ holds {held} committed episodes" in said
    assert "--total --episodes 50" in said
    last = json.loads((out / "meta/vcage_runs.jsonl").read_text().splitlines()[-1])
    assert last["ended"] == "interrupted" and last["dataset_episodes"] == held


def test_a_table_too_full_to_place_advises_less_clutter_not_more_attempts(tmp_path: Path) -> None:
    """Found on 2026-12-05: --clutter 500 failed every attempt at placement and advised raising
    --max-attempts, which cannot help."""
    out = tmp_path / "ds"
    result = RUN.invoke(app, ["generate", "press the bell", "--episodes", "1", "--out", str(out), "--clutter",
                              "500", "--size", "64", "--cameras", "front", "--max-attempts", "2"])
    said = " ".join(result.output.split())
    assert result.exit_code == 3, said
    assert "lower --clutter" in said and "raise --max-attempts" not in said
