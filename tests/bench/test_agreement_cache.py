"""``benchmarks/critic_agreement.py --cache``: Vanilla rollouts are stored once and re-judged from the
store (a changed critic is measured in seconds); an entry is written whole or not at all, and a
store filled by other code than the checkout's (outside ``vcage/critics``) is refused. The table is
split by how deep the plan's objects were fused into another object where the rollout started."""

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

from critic_agreement import FUSED  # noqa: E402
from obs_cache import STAMP, StaleCache, cached, fingerprint, open_cache  # noqa: E402

pytestmark = pytest.mark.slow  # runs a benchmark script over Vanilla rollouts


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
    assert "clear at the start            3     2     1      1  100.0%" in first
    # what is judged is what the store holds: an oracle verdict changed there changes the table
    with gzip.open(entry, "rb") as f:
        depth, judged = pickle.load(f)  # noqa: S301 - written by the run above
    assert depth <= FUSED
    i = next(k for k, (*_, success, _, _) in enumerate(judged) if success)
    scene, obs, _, where, _ = judged[i]
    judged[i] = (scene, obs, False, where, "{'stored': False}")
    with gzip.open(entry, "wb") as f:
        pickle.dump((depth, judged), f)
    again = _run(cache)
    assert "build_a_tower                 3     1     2      1   66.7%" in again
    assert f"false accept build_a_tower {where}: " in again
    # ... and so does the depth: stored deeper than the bound, the episode's subtasks change lines
    with gzip.open(entry, "wb") as f:
        pickle.dump((0.02, judged), f)
    fused = _run(cache)
    assert "clear at the start            0     0     0      0     n/a" in fused
    assert "interpenetrating              3     1     2      1   66.7%" in fused
    assert f"false accept build_a_tower {where} (starts interpenetrating: 20.0 mm): " in fused


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
    # the same code, but entries of the form before the start's depth was stored
    older = tmp_path / "older"
    open_cache(str(older), fingerprint())
    (older / "build_a_tower-3-lod.pkl.gz").write_bytes(b"a list of judged subtasks")
    done = _agreement(older)
    assert done.returncode != 0 and "give --cache a fresh directory" in done.stderr, done.stderr


def test_the_fingerprint_follows_the_package_but_not_its_critics(tmp_path: Path) -> None:
    root = tmp_path / "vcage"
    for part in ("critics", "tasks", "policy", "cli"):
        (root / part).mkdir(parents=True)
        (root / part / "x.py").write_text("A = 1\n")
    (root / "tasks" / "predicates.py").write_text("B = 1\n")
    first = fingerprint(root)
    for part in ("critics", "policy", "cli"):  # none of them can change a rollout
        (root / part / "x.py").write_text("A = 2\n")
        assert fingerprint(root) == first, part
    (root / "tasks" / "predicates.py").write_text("B = 2\n")
    assert fingerprint(root) != first
