"""``benchmarks/critic_agreement.py --cache``: Vanilla rollouts are stored once and re-judged from the
store (a changed critic is measured in seconds); an entry is written whole or not at all."""

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

from obs_cache import cached  # noqa: E402


def _run(cache: Path) -> str:
    out = subprocess.run([sys.executable, str(BENCHMARKS / "critic_agreement.py"), "--goals", "build_a_tower",
                          "--seeds", "1", "--first-seed", "3", "--workers", "1", "--cache", str(cache),
                          "--show-errors"], capture_output=True, text=True, timeout=600, check=True).stdout
    return re.sub(r"\d+ s wall", "", out)


def test_a_second_run_judges_the_stored_rollouts(tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    first = _run(cache)
    (entry,) = cache.iterdir()
    assert entry.name == "build_a_tower-3-lod.pkl.gz"
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
