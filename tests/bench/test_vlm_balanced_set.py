"""The VLM critic measured on the balanced set (``benchmarks/critic_failures.py --vlm-tape``): a model's
answers are recorded through the local tape endpoint, then replayed without the model, sample for
sample; a tape that lacks an answer fails the replay, and recording again asks only for what it
lacks. The model here is the local OpenAI-protocol server, answering from what it is asked."""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from backends.fake_openai import FakeOpenAI, Reply

pytestmark = pytest.mark.slow  # runs a benchmark script over the balanced set

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "critic_failures.py"


def _answer(body: dict[str, Any]) -> Reply:
    """Yes or no from the request's bytes: different samples get different answers, the same one the same."""
    digest = hashlib.sha256(json.dumps(body["messages"], sort_keys=True).encode()).digest()
    yes = digest[0] % 2 == 0
    return Reply(json.dumps({"success": yes, "reason": "yes" if yes else "no"}))


def _run(cache: Path, tape: Path, env: dict[str, str], *extra: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, str(SCRIPT), "--goals", "build_a_tower", "--seeds", "1",
                           "--faults-per-seed", "1", "--workers", "1", "--cache", str(cache), "--show-errors",
                           "--vlm-tape", str(tape), *extra],
                          env=env, capture_output=True, text=True, timeout=900, check=False)


def _vlm_part(out: str) -> list[str]:
    """The VLM critic's table and misjudged samples, without its title (which says recorded/replayed)."""
    lines = out.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("vlm ("))
    return lines[start + 1:]


def test_a_recorded_vlm_measurement_replays_answer_for_answer(tmp_path: Path) -> None:
    env = {k: v for k, v in os.environ.items() if not k.startswith("VCAGE_VLM_")}
    cache, tape = tmp_path / "cache", tmp_path / "vlm.jsonl"
    with FakeOpenAI(model="vision-1") as model:
        model.script(*[_answer] * 200)
        recorded = _run(cache, tape, {**env, "VCAGE_VLM_BASE_URL": model.base_url,
                                      "VCAGE_VLM_MODEL": "vision-1"}, "--vlm-record")
        asked = len(model.requests)
    assert recorded.returncode == 0, recorded.stderr
    table = _vlm_part(recorded.stdout)
    samples = int(table[1].split()[1]) + int(table[1].split()[2])  # the "all" row: successes + failures
    assert asked == samples == len(tape.read_text().splitlines())  # one question per sample, each kept
    assert any(line.startswith("  FA") for line in table) and any(line.startswith("  FR") for line in table)

    replayed = _run(cache, tape, env)  # no endpoint configured: the tape answers
    assert replayed.returncode == 0, replayed.stderr
    assert "replayed from vlm.jsonl" in replayed.stdout and _vlm_part(replayed.stdout) == table

    tape.write_text("\n".join(tape.read_text().splitlines()[:-1]) + "\n")  # one answer lost
    short = _run(cache, tape, env)
    assert short.returncode != 0 and "not on the tape" in short.stderr + short.stdout

    with FakeOpenAI(model="vision-1") as model:  # recording again asks only what the tape lacks
        model.script(*[_answer] * 200)
        again = _run(cache, tape, {**env, "VCAGE_VLM_BASE_URL": model.base_url,
                                   "VCAGE_VLM_MODEL": "vision-1"}, "--vlm-record")
        assert again.returncode == 0, again.stderr
        assert len(model.requests) == 1 and _vlm_part(again.stdout) == table
