"""Workers end with their parent: found on 2026-12-05, a ``kill -9`` of ``vcage generate --workers 2``
left both workers simulating (about 530 MB each) two minutes later."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # a real generation run with two worker processes


def _workers(parent: int) -> list[int]:
    """The pool workers (spawned interpreters) whose parent is ``parent``."""
    out = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            cmdline = (entry / "cmdline").read_bytes()
        except OSError:
            continue
        ppid = int(stat.rsplit(")", 1)[1].split()[1])
        if ppid == parent and b"spawn_main" in cmdline:
            out.append(int(entry.name))
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the parent-death signal is Linux's")
def test_a_killed_generate_run_takes_its_workers_with_it(tmp_path: Path) -> None:
    args = ["generate", "press the bell", "--episodes", "20", "--workers", "2", "--out", str(tmp_path / "ds"),
            "--critic", "oracle", "--clutter", "0", "--size", "64", "--cameras", "front"]
    run = subprocess.Popen([sys.executable, "-m", "vcage.cli", *args], stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 120
        workers: list[int] = []
        while len(workers) < 2 and time.monotonic() < deadline and run.poll() is None:
            time.sleep(0.5)
            workers = _workers(run.pid)
        assert len(workers) == 2, "the run did not start two workers"
        time.sleep(2)  # the workers are running episodes
        os.kill(run.pid, signal.SIGKILL)
        run.wait(10)
        deadline = time.monotonic() + 15
        while any(_alive(w) for w in workers) and time.monotonic() < deadline:
            time.sleep(0.2)
        left = [w for w in workers if _alive(w)]
        for w in left:
            os.kill(w, signal.SIGKILL)
        assert not left, f"workers {left} outlived their killed parent"
    finally:
        if run.poll() is None:
            run.kill()
