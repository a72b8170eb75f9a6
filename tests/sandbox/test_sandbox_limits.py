"""The child's limits: wall-clock kill of the whole process group, CPU, memory, a strict protocol."""

from __future__ import annotations

import subprocess
import time
from pathlib import Path

import pytest
from sandbox_escape_corpus import skills, snapshot

from vcage.errors import ConfigError
from vcage.sandbox import Limits, run_program
from vcage.sandbox.protocol import parse_answer
from vcage.sandbox.runner import kill_group


def test_a_looping_program_is_killed_at_the_wall_clock_limit() -> None:
    limits = Limits(cpu_seconds=30, wall_seconds=0.5)
    t0 = time.perf_counter()
    result = run_program("while True:\n    pass\n", skills(), snapshot(), limits)
    elapsed = time.perf_counter() - t0
    assert result.status == "timeout" and "killed" in result.error
    assert elapsed < limits.wall_seconds + 1.0


def test_the_cpu_limit_stops_a_program_before_the_wall_clock() -> None:
    result = run_program("x = 0\nwhile True:\n    x = x + 1\n", skills(), snapshot(),
                         Limits(cpu_seconds=1, wall_seconds=20))
    assert result.status == "cpu_limit"
    assert result.seconds < 5


def test_memory_bombs_hit_the_address_space_limit() -> None:
    for code in ("x = [0] * 10 ** 9\n", "x = 'a' * 10 ** 10\n"):
        result = run_program(code, skills(), snapshot(), Limits(memory_mb=128))
        assert result.status == "memory_limit", result
        assert result.line == 1


def test_killing_the_group_takes_the_grandchildren_too() -> None:
    proc = subprocess.Popen(["sh", "-c", "sleep 60 & echo $!; wait"], stdout=subprocess.PIPE,
                            start_new_session=True)
    assert proc.stdout is not None
    grandchild = int(proc.stdout.readline())
    assert _alive(grandchild)
    kill_group(proc)
    deadline = time.monotonic() + 2
    while _alive(grandchild) and time.monotonic() < deadline:
        time.sleep(0.02)
    assert not _alive(grandchild)


def _alive(pid: int) -> bool:
    """Running (a killed process that nobody reaped yet is a zombie: state Z)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except FileNotFoundError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


def test_runtime_errors_say_what_and_where() -> None:
    result = run_program("x = 1\ny = position('ghost')\n", skills(), snapshot())
    assert result.status == "runtime_error" and result.line == 2
    assert "no object 'ghost'" in result.error
    missing = run_program("press()\n", skills(), snapshot())
    assert missing.status == "runtime_error" and "needs argument(s) ['obj']" in missing.error


def test_reruns_record_identical_calls() -> None:
    code = ("for name in objects():\n    p = pose(name)\n"
            "    pick_and_place(obj=name, xy=(p[0] + 0.05, p[1]))\n")
    first = run_program(code, skills(), snapshot())
    second = run_program(code, skills(), snapshot())
    assert first.ok and first.calls == second.calls and len(first.calls) == 2


@pytest.mark.parametrize("answer", [b"", b"not json", b"[1, 2]", b'{"ok": "yes"}',
                                    b'{"ok": true, "calls": [{"skill": "press"}], "log": []}',
                                    b'{"ok": true, "calls": [{"skill": "press", "args": {}, "x": 1}], '
                                    b'"log": []}',
                                    b"\x80\x04\x95pickle"])
def test_answers_outside_the_protocol_are_bad_output(answer: bytes) -> None:
    assert parse_answer(answer, 0.0).status == "bad_output"


def test_limits_are_checked() -> None:
    with pytest.raises(ConfigError, match="wall_seconds"):
        Limits(wall_seconds=0)
    with pytest.raises(ConfigError, match="memory_mb"):
        Limits(memory_mb=10)
