"""The software an episode depends on, by version and by code: stored with what vcage makes.

The same seed gives the same episode only under the same code and the same versions of the
simulator and the solvers around it (MuJoCo's contacts, mink's and daqp's inverse kinematics, NumPy's
random streams): the rollouts of one commit were seen to differ between two machines that resolved
the dependencies at different times, and a patch release of MuJoCo moved them. So a run records
the versions of the distributions that decide an episode, the code it ran (the git commit of a
checkout, with a flag when its files differ from the commit, and always a digest of the package's
own files, which tells code apart where there is no checkout) and the hash of the lock file the
environment was installed from. Versions are read from the installed distributions' metadata, so
nothing here imports the simulator.
"""

from __future__ import annotations

import functools
import hashlib
import platform
import subprocess
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

# the distributions whose versions decide what an episode holds
DISTRIBUTIONS = ("vcage", "mujoco", "mujoco-core", "mink", "daqp", "numpy", "scipy", "shapely", "trimesh",
                 "fast-simplification", "av")
LOCK_FILE = Path("requirements") / "lock.txt"  # relative to a checkout's top
PACKAGE = Path(__file__).resolve().parent


def software() -> dict[str, str]:
    """:func:`versions`, :func:`code` and :func:`numerics`: everything a run records of the software
    it ran."""
    return {**versions(), **code(), **numerics()}


@functools.cache
def numerics() -> dict[str, str]:
    """``blas``: the kernels NumPy's OpenBLAS runs (:mod:`vcage.numerics`), which decide the last bits
    of the inverse kinematics and so where a chaotic rollout ends."""
    from vcage.numerics import blas_core

    return {"blas": blas_core()}


def versions() -> dict[str, str]:
    """``{distribution: version}`` for :data:`DISTRIBUTIONS` and Python ("absent" where one is not
    installed)."""
    out = {"python": platform.python_version()}
    for name in DISTRIBUTIONS:
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = "absent"
    return out


@functools.cache
def code() -> dict[str, str]:
    """What tells this code apart from other code of the same version: ``source`` (a digest of the
    package's files), ``commit`` (the checkout's git commit, ``+dirty`` when the package, the lock
    file or ``pyproject.toml`` differ from it; "absent" outside a checkout) and ``lock`` (a digest of
    the checkout's lock file; "absent" without one)."""
    top = _checkout()
    return {"source": source_digest(), "commit": _commit(top) if top else "absent",
            "lock": _digest(top / LOCK_FILE) if top and (top / LOCK_FILE).is_file() else "absent"}


def source_digest(root: Path = PACKAGE) -> str:
    """A digest of the files of the package at ``root`` (paths and contents; caches left out)."""
    digest = hashlib.sha256()
    for path in sorted(p for p in root.rglob("*") if p.is_file() and "__pycache__" not in p.parts):
        digest.update(path.relative_to(root).as_posix().encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()[:16]


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()[:16]


def _git(top: Path, *args: str) -> str | None:
    try:
        done = subprocess.run(["git", "-C", str(top), *args], capture_output=True, text=True, timeout=10,
                              check=False)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return done.stdout.strip() if done.returncode == 0 else None


def _checkout(package: Path = PACKAGE) -> Path | None:
    """The top of the git checkout whose ``src/vcage`` is ``package`` (an editable install), or None."""
    top = _git(package, "rev-parse", "--show-toplevel")
    if top is None or (Path(top) / "src" / "vcage").resolve() != package.resolve():
        return None
    return Path(top)


def _commit(top: Path) -> str:
    head = _git(top, "rev-parse", "HEAD")
    if head is None:
        return "absent"
    changed = _git(top, "status", "--porcelain", "--", "src", str(LOCK_FILE),
                   "pyproject.toml")
    return head + ("+dirty" if changed else "")
