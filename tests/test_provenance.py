"""A run records the code it ran beside the versions: the checkout's commit (flagged when its files
differ), a digest of the package's files and the lock file's hash."""

from __future__ import annotations

import hashlib
import shutil
import subprocess
from pathlib import Path

import vcage
from vcage import provenance
from vcage.provenance import LOCK_FILE, code, software, source_digest, versions

TOP = Path(__file__).resolve().parents[1]


def test_the_checkout_s_commit_and_lock_are_recorded() -> None:
    recorded = code()
    head = subprocess.run(["git", "-C", str(TOP), "rev-parse", "HEAD"], capture_output=True, text=True,
                          check=True).stdout.strip()
    assert recorded["commit"].removesuffix("+dirty") == head
    assert recorded["lock"] == hashlib.sha256((TOP / LOCK_FILE).read_bytes()).hexdigest()[:16]
    assert recorded["source"] == source_digest()
    assert software() == {**versions(), **recorded}
    assert versions()["mujoco"] == versions()["mujoco-core"]  # released together
    assert versions()["vcage"] == vcage.__version__  # one version, read by the build from the package


def test_the_source_digest_tells_code_apart(tmp_path: Path) -> None:
    copy = tmp_path / "vcage"
    shutil.copytree(provenance.PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    assert source_digest(copy) == source_digest()
    (copy / "__pycache__").mkdir(exist_ok=True)
    (copy / "__pycache__" / "x.pyc").write_bytes(b"cache")  # caches do not count
    assert source_digest(copy) == source_digest()
    critic = copy / "critics" / "image.py"
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
