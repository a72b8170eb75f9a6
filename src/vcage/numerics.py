"""The same linear-algebra kernels on every x86-64 machine, so that a seed gives the same episode.

OpenBLAS (which NumPy ships, and which the inverse kinematics' least squares and solves call) picks
its kernels by the CPU it runs on: AVX-512 kernels on one machine, Haswell's on another, each
summing in its own order. The last bits differ, and a rollout that is chaotic (a Vanilla scene
whose objects start fused, a tower that may topple) ends elsewhere: three stored Vanilla rollouts
of ``tests/regenerate`` came out moved on an AMD EPYC without AVX-512, their code, versions and
seeds the same (2026-12-07); each of OpenBLAS's kernels that CPU can run moved them, none back to
what the machine that stored them (likely one with AVX-512 kernels) had seen.

:func:`pin` sets ``OPENBLAS_CORETYPE=Haswell`` (AVX2 and FMA, which every x86-64 server of the last
decade has) before NumPy loads OpenBLAS, unless the variable is already set or the CPU lacks AVX2
or FMA (then OpenBLAS chooses, and the run records which). ``vcage/__init__`` calls it first, so the
command line, its workers and the tests are pinned; a program that imports NumPy before vcage keeps
what OpenBLAS chose. :func:`blas_core` says what was chosen; provenance records it with every run.
"""

from __future__ import annotations

import os
import platform
import sys
from pathlib import Path

CORE = "Haswell"
VARIABLE = "OPENBLAS_CORETYPE"
NEEDS = ("avx2", "fma")  # what the pinned kernels execute
# the function that names the kernels, in NumPy's OpenBLAS (64-bit, prefixed) and in a plain one
SYMBOLS = ("scipy_openblas_get_corename64_", "scipy_openblas_get_corename", "openblas_get_corename")


def _cpu_flags() -> set[str]:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("flags"):
                return set(line.split(":", 1)[1].split())
    except OSError:
        pass
    return set()


def pin() -> str:
    """Pin OpenBLAS's kernels if NumPy is not loaded yet; what happened, in words."""
    if VARIABLE in os.environ:
        return f"{VARIABLE}={os.environ[VARIABLE]} (set before vcage)"
    if platform.machine() not in ("x86_64", "AMD64"):
        return f"not pinned: {platform.machine()}"
    if "numpy" in sys.modules:
        return "not pinned: numpy was imported before vcage"
    if not set(NEEDS) <= _cpu_flags():
        return f"not pinned: the CPU lacks {' or '.join(n for n in NEEDS if n not in _cpu_flags())}"
    os.environ[VARIABLE] = CORE
    return f"{VARIABLE}={CORE}"


def blas_core() -> str:
    """The kernels the OpenBLAS that NumPy loaded runs ("Haswell", "SkylakeX", ...), read from the
    library itself; "unknown" where it cannot be read (another BLAS, no OpenBLAS loaded)."""
    import ctypes

    import numpy as np  # noqa: F401 - loads its OpenBLAS

    try:
        maps = Path("/proc/self/maps").read_text().splitlines()
    except OSError:
        return "unknown"
    libs = sorted({ln.split()[-1] for ln in maps if "openblas" in ln.rsplit("/", 1)[-1].lower()})
    for lib in libs:
        handle = ctypes.CDLL(lib)
        for symbol in SYMBOLS:
            fn = getattr(handle, symbol, None)
            if fn is not None:
                fn.restype = ctypes.c_char_p
                return str(fn().decode())
    return "unknown"
