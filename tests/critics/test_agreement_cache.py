"""``benchmarks/critic_agreement.py --cache``: Vanilla rollouts are stored once and re-judged from the
store (a changed critic is measured in seconds); an entry is written whole or not at all, and a
store filled by other code than the checkout's (outside ``vcage/critics``) is refused."""

from __future__ import annotations

import gzip
import pickle
import re
import subprocess
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
sys.path.insert(0, str(BENCHMARKS))

from obs_cache import STAMP, StaleCache, cached, fingerprint, open_cache  # noqa: E402


def _agreement(cache: Path) -> subprocess.CompletedProcess[str]:
    script = str(BENCHMARKS / "critic_agreement.py")
    return subprocess.run([sys.executable, script, "--goals", "build_a_tower", "--seeds", "1",
                           "--first-seed", "3", "--workers", "1", "--cache", str(cache), "--show-errors"],
                          capture_output=True, text=True, timeout=600, check=False)


def _run(cache: Path) -> str:
    done = _agreement(cache)
    assert done.returncode == 0, done.stderr
    return re.sub(r"\d+ s wall", "", done.stdout)


def test_a_second_run_judges_the_stored_rollouts(tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    first = _run(cache)
    assert sorted(p.name for p in cache.iterdir()) == [STAMP, "build_a_tower-3-lod.pkl.gz"]
    entry = cache / "build_a_tower-3-lod.pkl.gz"
    assert "build_a_tower                 3     2     1      1  100.0%" in first
    assert _run(cache) == first
    # what is judged is what the store holds: an oracle verdict changed there changes the table
    with gzip.open(entry, "rb") as f:
        judged = pickle.load(f)  # noqa: S301 - written by the run above
    i = next(k for k, (*_, success, _, _) in enumerate(judged) if success)
    scene, obs, _, where, _ = judged[i]
    judged[i] = (scene, obs, False, where, "{'stored': False}")
    with gzip.open(entry, "wb") as f:
        pickle.dump(judged, f)
    again = _run(cache)
    assert "build_a_tower                 3     1     2      1   66.7%" in again
    assert f"false accept build_a_tower {where}: " in again


def test_an_entry_that_cannot_be_written_leaves_nothing_behind(tmp_path: Path) -> None:
    path = tmp_path / "x.pkl.gz"
    with pytest.raises((pickle.PicklingError, AttributeError, TypeError)):
        cached(path, lambda: [1, lambda: 2])  # a lambda cannot be pickled: the write fails midway
    assert list(tmp_path.iterdir()) == []
    assert cached(path, lambda: 7) == 7
    assert cached(path, lambda: 8) == 7  # stored: not made again
    assert [p.name for p in tmp_path.iterdir()] == ["x.pkl.gz"]


def test_a_store_filled_by_other_code_is_refused(tmp_path: Path) -> None:
    """Rollouts depend on the oracle, skills and physics: after a change there, stored ones are stale."""
    cache = tmp_path / "cache"
    open_cache(str(cache), "made-by-other-code")
    (cache / "build_a_tower-3-lod.pkl.gz").write_bytes(b"stale")
    done = _agreement(cache)
    assert done.returncode != 0 and "give --cache a fresh directory" in done.stderr, done.stderr
    assert (cache / "build_a_tower-3-lod.pkl.gz").read_bytes() == b"stale"  # left as it was
    unstamped = tmp_path / "old"
    unstamped.mkdir()
    (unstamped / "x.pkl.gz").write_bytes(b"")
    with pytest.raises(StaleCache, match="no SOURCE stamp"):
        open_cache(str(unstamped))
    assert open_cache(str(tmp_path / "new")) == tmp_path / "new"  # a fresh one is stamped
    assert (tmp_path / "new" / STAMP).read_text().strip() == fingerprint()


def test_the_fingerprint_follows_the_package_but_not_its_critics(tmp_path: Path) -> None:
    root = tmp_path / "vcage"
    (root / "critics").mkdir(parents=True)
    (root / "tasks").mkdir()
    (root / "critics" / "image.py").write_text("A = 1\n")
    (root / "tasks" / "predicates.py").write_text("B = 1\n")
    first = fingerprint(root)
    (root / "critics" / "image.py").write_text("A = 2\n")
    assert fingerprint(root) == first
    (root / "tasks" / "predicates.py").write_text("B = 2\n")
    assert fingerprint(root) != first
