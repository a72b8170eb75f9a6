"""A run records the code it ran beside the versions: the checkout's commit (flagged when its files
differ), a digest of the package's files and the lock file's hash."""

from __future__ import annotations

import hashlib
import shutil
import subprocess
from pathlib import Path

import pytest

import vcage
from vcage import provenance
from vcage.numerics import blas_core
from vcage.provenance import LOCK_FILE, code, software, source_digest, versions

TOP = Path(__file__).resolve().parents[1]


def test_the_checkout_s_commit_and_lock_are_recorded() -> None:
    recorded = code()
    head = subprocess.run(["git", "-C", str(TOP), "rev-parse", "HEAD"], capture_output=True, text=True,
                          check=True).stdout.strip()
    assert recorded["commit"].removesuffix("+dirty") == head
    assert recorded["lock"] == hashlib.sha256((TOP / LOCK_FILE).read_bytes()).hexdigest()[:16]
    assert recorded["source"] == source_digest()
    assert software() == {**versions(), **recorded, "blas": blas_core()}
    assert versions()["mujoco"] == versions()["mujoco-core"]  # released together
    assert versions()["vcage"] == vcage.__version__  # one version, read by the build from the package


def test_the_source_digest_tells_code_apart(tmp_path: Path) -> None:
    copy = tmp_path / "vcage"
    shutil.copytree(provenance.PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    assert source_digest(copy) == source_digest()
    (copy / "__pycache__").mkdir(exist_ok=True)
    (copy / "__pycache__" / "x.pyc").write_bytes(b"cache")  # caches do not count
    assert source_digest(copy) == source_digest()
    critic = copy / "critics" / "image" / "support.py"
    critic.write_text(critic.read_text() + "\n# one more line\n")
    assert source_digest(copy) != source_digest()


def test_a_changed_file_in_the_checkout_marks_the_commit_dirty(tmp_path: Path) -> None:
    """A clone of the checkout whose package file changed records ``+dirty``; the same clone clean
    records its commit alone; a copy outside any checkout records no commit and no lock."""
    clone = tmp_path / "clone"
    subprocess.run(["git", "clone", "-q", "--no-local", str(TOP), str(clone)], check=True)
    pkg = clone / "src" / "vcage"
    assert provenance._checkout(pkg) == clone
    assert provenance._commit(clone).endswith(tuple("0123456789abcdef"))
    (pkg / "errors.py").write_text((pkg / "errors.py").read_text() + "\n")
    assert provenance._commit(clone).endswith("+dirty")
    loose = tmp_path / "loose"
    shutil.copytree(pkg, loose / "vcage", ignore=shutil.ignore_patterns("__pycache__"))
    assert provenance._checkout(loose / "vcage") is None
    (clone / "elsewhere").mkdir()
    shutil.copytree(pkg, clone / "elsewhere" / "vcage")  # in a checkout, but not as its src/vcage
    assert provenance._checkout(clone / "elsewhere" / "vcage") is None


def test_every_x86_64_run_uses_the_same_blas_kernels() -> None:
    """OpenBLAS's kernels decide the last bits of the IK, and so where a chaotic rollout ends: vcage
    pins them before NumPy loads them (the test process imported vcage first, via conftest), a child
    that imports vcage first is pinned too, and one that imports NumPy first is told it was not."""
    import os
    import sys

    from vcage.numerics import CORE, NEEDS, VARIABLE, _cpu_flags

    if not set(NEEDS) <= _cpu_flags():
        pytest.skip("the CPU lacks AVX2 or FMA: OpenBLAS chooses its kernels")
    assert os.environ.get(VARIABLE) == CORE and blas_core() == CORE and software()["blas"] == CORE
    env = {k: v for k, v in os.environ.items() if k != VARIABLE}
    first = "import vcage, os; from vcage.numerics import blas_core; print(vcage.NUMERICS, '|', blas_core())"
    out = subprocess.run([sys.executable, "-c", first], capture_output=True, text=True, env=env, check=True)
    assert out.stdout.split() == [f"{VARIABLE}={CORE}", "|", CORE]
    late = "import numpy, vcage; print(vcage.NUMERICS)"
    out = subprocess.run([sys.executable, "-c", late], capture_output=True, text=True, env=env, check=True)
    assert out.stdout.strip() == "not pinned: numpy was imported before vcage"
    mine = subprocess.run([sys.executable, "-c", first], capture_output=True, text=True, check=True,
                          env={**env, VARIABLE: "Sandybridge"})
    assert mine.stdout.split() == [f"{VARIABLE}=Sandybridge", "(set", "before", "vcage)", "|", "Sandybridge"]

