"""Fault injection: ``kill -9`` at many points of a generation run, then the same command again.

Whatever the kill interrupted (simulation, video encoding, the files of an episode, the shared
data and video files the second episode joins, the meta files, the commit, the attempt log),
rerunning ``vcage generate ... --total`` must leave a dataset that verifies clean, holds exactly
the episodes asked for, byte for byte the episodes of an uninterrupted run, and an attempt log
that matches it.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from vcage.data import DatasetReader
from vcage.data.layout import ATTEMPTS_LOG
from vcage.data.verify import verify
from vcage.pipeline.attempt_log import read

pytestmark = pytest.mark.slow  # SIGKILL trials of real generation runs

EPISODES = 2
TIMED_KILLS = 10  # at evenly spread moments of the run
# in the write windows of both episodes: right after the n-th temporary file of the run appears, or
# a few milliseconds later (a 1 ms poll sees about 9 per run on an idle machine, fewer when loaded:
# each episode's data, video, extras and states, then some meta files)
WINDOW_KILLS = ((1, 0.0), (2, 0.0), (3, 0.0), (4, 0.0), (5, 0.0), (6, 0.0), (7, 0.0), (2, 0.003),
                (4, 0.003), (6, 0.003))
# while the second episode, which joins the first one's data and video files, replaces them: right
# after the first backup of a shared file appears (it lives until the episode commits), or later
BACKUP_KILLS = (0.0, 0.002, 0.005)
COMPARED = ("*.parquet", "*.mp4", "*.npz")


def _command(out: Path) -> list[str]:
    return [sys.executable, "-m", "vcage.cli", "generate", "press the bell", "--episodes", str(EPISODES),
            "--total", "--out", str(out), "--critic", "oracle", "--clutter", "0", "--size", "64",
            "--cameras", "front", "--seed", "11"]


def _run(out: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(_command(out), capture_output=True, text=True, timeout=300,
                          env={**os.environ, "COLUMNS": "200"})


def _temporaries(root: Path, mark: str = ".tmp-") -> set[str]:
    if not root.exists():
        return set()
    return {os.path.join(d, f) for d, _, files in os.walk(root) for f in files if mark in f}


def _kill(proc: subprocess.Popen[bytes], out: Path, at: float | None, nth_temporary: int,
          delay: float = 0.0, mark: str = ".tmp-") -> str:
    """SIGKILL ``proc`` at ``at`` seconds, or ``delay`` after it created ``nth_temporary`` files
    whose names hold ``mark`` (temporary files, or backups)."""
    start, seen = time.perf_counter(), set()
    while proc.poll() is None:
        if at is not None and time.perf_counter() - start >= at:
            break
        if at is None:
            seen |= _temporaries(out, mark)
            if len(seen) >= nth_temporary:
                time.sleep(delay)
                break
        time.sleep(0.001 if at is None else 0.01)
    if proc.poll() is not None:
        return "finished first"
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    return "killed"


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, float]:
    out = tmp_path_factory.mktemp("clean") / "ds"
    t0 = time.perf_counter()
    done = _run(out)
    assert done.returncode == 0, done.stdout + done.stderr
    shared = sorted(p.name for p in out.rglob("file-*.*") if "meta" not in p.parts)
    assert shared == ["file-000.mp4", "file-000.parquet"]  # the second episode joined the first's files
    return out, time.perf_counter() - t0


def _files(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for pattern in COMPARED for p in root.rglob(pattern)}


@pytest.mark.parametrize("trial", range(TIMED_KILLS + len(WINDOW_KILLS) + len(BACKUP_KILLS)))
def test_kill_9_then_rerun_completes_the_same_dataset(trial: int, tmp_path: Path,
                                                      reference: tuple[Path, float]) -> None:
    clean, seconds = reference
    out = tmp_path / "ds"
    proc = subprocess.Popen(_command(out), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    if trial < TIMED_KILLS:  # from start-up to late in the second episode
        at = 0.3 + 0.7 * seconds * trial / TIMED_KILLS
        outcome = _kill(proc, out, at=at, nth_temporary=0)
        for _ in range(3):  # this run was quicker than the reference: start again, kill earlier
            if outcome == "killed":
                break
            shutil.rmtree(out)
            at *= 0.7
            proc = subprocess.Popen(_command(out), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            outcome = _kill(proc, out, at=at, nth_temporary=0)
    elif trial < TIMED_KILLS + len(WINDOW_KILLS):
        nth, delay = WINDOW_KILLS[trial - TIMED_KILLS]
        outcome = _kill(proc, out, at=None, nth_temporary=nth, delay=delay)
    else:
        delay = BACKUP_KILLS[trial - TIMED_KILLS - len(WINDOW_KILLS)]
        outcome = _kill(proc, out, at=None, nth_temporary=1, delay=delay, mark=".keep-")
    assert outcome == "killed"  # the kill landed while the run was going on
    rerun = _run(out)
    if rerun.returncode == 5:  # killed between an episode's meta rows and its commit: the documented path
        assert "--repair" in " ".join(rerun.stdout.split()), rerun.stdout
        repaired = subprocess.run([sys.executable, "-m", "vcage.cli", "verify", str(out), "--repair"],
                                  capture_output=True, text=True, timeout=300)
        assert repaired.returncode == 0, repaired.stdout + repaired.stderr
        rerun = _run(out)
    assert rerun.returncode == 0, (outcome, rerun.stdout + rerun.stderr)
    report = verify(out)
    assert report.ok, report.summary()
    reader = DatasetReader(out)
    assert reader.num_episodes == EPISODES
    assert _files(out) == _files(clean)  # the very episodes of an uninterrupted run
    seeds = [reader.extras(i)["seed"] for i in range(EPISODES)]
    log = read(out / ATTEMPTS_LOG)
    assert sorted(r["seed"] for r in log if r["stage"] == "accepted") == sorted(seeds)
    assert log == read(clean / ATTEMPTS_LOG)
    assert not _temporaries(out) and not _temporaries(out, ".keep-")
    assert not (out / "meta" / ".vcage.lock").exists()
