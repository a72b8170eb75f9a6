"""The dynamic half of the sandbox: run a checked program in a child process, under limits.

Generated code never runs in the parent process. :func:`run_program` first checks it statically
(:func:`vcage.sandbox.policy.check`; a refusal is the run's ``rejected`` outcome), then starts
``python -I -S child.py`` (isolated mode: no user site, no environment variables read, no script
directory on the path; no ``site``) with an **empty environment** (no API keys), in an **empty
temporary directory**, in a **new session** (its own process group). The child lowers its own CPU,
address-space, file-size (0: no writes), process and file-descriptor limits and refuses every
audited event (files, sockets, imports, fork/exec) before the program runs; see
:mod:`vcage.sandbox.child`. A child still alive after ``wall_seconds`` is killed with its whole
process group (SIGKILL). The answer is JSON, read strictly (:mod:`vcage.sandbox.protocol`).
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

from vcage.errors import CodeRejectedError, ConfigError, SandboxError
from vcage.sandbox.policy import check
from vcage.sandbox.protocol import (
    CPU,
    CRASHED,
    QUERIES,
    REJECTED,
    TIMEOUT,
    RunResult,
    SceneSnapshot,
    SkillSignature,
    parse_answer,
    request,
)

CHILD = Path(__file__).with_name("child.py")
MAX_STDERR = 2000  # characters of the child's stderr kept in a crash report


@dataclass(frozen=True)
class Limits:
    """What one program may use: CPU seconds, memory (address space), wall-clock seconds, calls."""

    cpu_seconds: int = 2
    memory_mb: int = 256
    wall_seconds: float = 5.0
    max_calls: int = 32

    def __post_init__(self) -> None:
        if not 1 <= self.cpu_seconds <= 60:
            raise ConfigError(f"sandbox cpu_seconds {self.cpu_seconds} must lie in [1, 60]")
        if not 64 <= self.memory_mb <= 8192:
            raise ConfigError(f"sandbox memory_mb {self.memory_mb} must lie in [64, 8192]")
        if not 0.1 <= self.wall_seconds <= 120:
            raise ConfigError(f"sandbox wall_seconds {self.wall_seconds} must lie in [0.1, 120]")
        if not 1 <= self.max_calls <= 256:
            raise ConfigError(f"sandbox max_calls {self.max_calls} must lie in [1, 256]")

    def for_child(self) -> dict[str, float]:
        return {"cpu_seconds": self.cpu_seconds, "memory_bytes": self.memory_mb * 2**20,
                "max_calls": self.max_calls}

    def to_dict(self) -> dict[str, float]:
        return asdict(self)


def run_program(code: str, api: Sequence[SkillSignature], scene: SceneSnapshot,
                limits: Limits = Limits()) -> RunResult:
    """Check ``code``, run it in a child process and return what it recorded (or why it did not).

    Every outcome of the program is a :class:`RunResult`; only a child that cannot be started at all
    raises :class:`SandboxError`.
    """
    t0 = time.perf_counter()
    try:
        check(code, [s.name for s in api] + list(QUERIES))
    except CodeRejectedError as exc:
        return RunResult(REJECTED, error=str(exc), seconds=time.perf_counter() - t0)
    return execute(code, api, scene, limits, t0)


def execute(code: str, api: Sequence[SkillSignature], scene: SceneSnapshot, limits: Limits = Limits(),
            t0: float | None = None) -> RunResult:
    """Run ``code`` in the child **without** the static check: the second layer alone.

    For tests and benchmarks that show the child's limits and audit hook hold by themselves; every
    other caller goes through :func:`run_program`.
    """
    t0 = time.perf_counter() if t0 is None else t0
    payload = request(code, api, scene, limits.for_child())
    with tempfile.TemporaryDirectory(prefix="vcage-sandbox-") as cwd:
        os.chmod(cwd, 0o555)  # nothing to read, nowhere to write
        try:
            proc = subprocess.Popen([sys.executable, "-I", "-S", str(CHILD)], stdin=subprocess.PIPE,
                                    stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=cwd, env={},
                                    close_fds=True, start_new_session=True)
        except OSError as exc:
            raise SandboxError(f"cannot start the sandbox child ({sys.executable}): {exc}; check that the "
                               "Python interpreter is executable") from exc
        try:
            out, err = proc.communicate(payload, timeout=limits.wall_seconds)
        except subprocess.TimeoutExpired:
            kill_group(proc)
            return RunResult(TIMEOUT, error=f"still running after {limits.wall_seconds} s (killed)",
                             seconds=time.perf_counter() - t0)
    seconds = time.perf_counter() - t0
    if proc.returncode in (-signal.SIGXCPU, -signal.SIGKILL):
        return RunResult(CPU, error=f"used more than {limits.cpu_seconds} s of CPU (killed)", seconds=seconds)
    if proc.returncode != 0:
        tail = err.decode("utf-8", "replace")[-MAX_STDERR:]
        return RunResult(CRASHED, error=f"the child exited with status {proc.returncode}: {tail}",
                         seconds=seconds)
    return parse_answer(out, seconds)


def kill_group(proc: subprocess.Popen[bytes]) -> None:
    """SIGKILL the child's whole process group and reap it."""
    with contextlib.suppress(ProcessLookupError):
        os.killpg(proc.pid, signal.SIGKILL)
    proc.communicate()
