"""New per-frame features for an existing dataset: each episode's values land in its own rows of
the shared files, the metadata follows, and bad values change nothing."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from vcage.data import DatasetReader, DatasetWriter, Feature, verify
from vcage.data.columns import add_features
from vcage.errors import CorruptDatasetError, DatasetError

FEATURES = {"observation.state": Feature("float32", (32,)), "action": Feature("float32", (2,))}
LENGTHS = (50, 70, 40, 60)
NEW = {"progress": Feature("float32", (1,)), "marker": Feature("int64", (2,), names=["a", "b"])}


def values(index: int) -> dict[str, np.ndarray]:
    length = LENGTHS[index]
    return {"progress": np.linspace(0, 1, length, dtype=np.float32)[:, None] + index,
            "marker": np.column_stack([np.full(length, index), np.arange(length)])}


def write(root: Path, lengths: tuple[int, ...], **kw: float) -> None:
    with DatasetWriter(root, fps=10, features=FEATURES, config={"c": 1}, chunks_size=2, **kw) as w:
        for i, n in enumerate(lengths):
            state = np.random.default_rng(i).normal(size=(n, 32)).astype(np.float32)
            state[:, 0] = i
            w.add_episode({"observation.state": state, "action": np.zeros((n, 2), np.float32)}, task="t")


@pytest.fixture()
def ds(tmp_path: Path) -> Path:
    write(tmp_path / "one", LENGTHS[:1])
    size = next((tmp_path / "one/data").rglob("*.parquet")).stat().st_size
    root = tmp_path / "ds"
    write(root, LENGTHS, data_files_size_in_mb=2.4 * size / 2**20)  # two episodes a file
    return root


def contents(root: Path) -> dict[str, bytes]:
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def test_each_episode_gets_its_own_values_and_the_metadata_follows(ds: Path) -> None:
    files = sorted(p.relative_to(ds).as_posix() for p in (ds / "data").rglob("*.parquet"))
    assert files == ["data/chunk-000/file-000.parquet", "data/chunk-000/file-001.parquet"]
    assert add_features(ds, NEW, values) == 2
    reader = DatasetReader(ds)
    assert reader.features["marker"] == NEW["marker"]
    for i in range(len(LENGTHS)):
        frames = reader.episode(i).frames
        np.testing.assert_array_equal(frames["marker"], values(i)["marker"])
        np.testing.assert_allclose(frames["progress"].ravel(), values(i)["progress"].ravel())
        np.testing.assert_array_equal(frames["observation.state"][:, 0], i)
        assert reader.episode_meta(i)["stats/marker/max"] == [i, LENGTHS[i] - 1]
    stats = json.loads((ds / "meta/stats.json").read_text())
    assert stats["progress"]["max"] == [4.0] and stats["marker"]["count"] == [sum(LENGTHS)]
    marker = json.loads((ds / "meta/vcage.json").read_text())
    assert "marker" in marker["info"]["features"]
    assert verify(ds).ok
    assert add_features(ds, NEW, values) == 0  # already there
    with DatasetWriter(ds, fps=10, features={**FEATURES, **NEW}, config={"c": 1}, chunks_size=2) as w:
        zeros = {k: np.zeros((3, f.shape[0]), np.dtype(f.dtype)) for k, f in {**FEATURES, **NEW}.items()}
        w.add_episode(zeros, task="t")
    assert verify(ds).ok and DatasetReader(ds).episode(4).frames["marker"].shape == (3, 2)


@pytest.mark.parametrize("bad", ["shape", "nan", "missing"])
def test_bad_values_are_refused_naming_the_episode_and_change_nothing(ds: Path, bad: str) -> None:
    before = contents(ds)

    def broken(index: int) -> dict[str, np.ndarray]:
        out = values(index)
        if index == 2:
            if bad == "shape":
                out["marker"] = out["marker"][:-1]
            elif bad == "nan":
                out["progress"][1] = np.nan
            else:
                del out["marker"]
        return out

    with pytest.raises(DatasetError, match="episode 2"):
        add_features(ds, NEW, broken)
    after = contents(ds)
    meta = [k for k in before if not k.startswith("data/")]
    assert {k: after[k] for k in meta} == {k: before[k] for k in meta}  # nothing committed
    assert DatasetReader(ds).features.keys() == FEATURES.keys() and verify(ds).ok


def test_names_that_clash_and_damaged_datasets_are_refused(ds: Path) -> None:
    with pytest.raises(DatasetError, match="clash"):
        add_features(ds, {"timestamp": Feature("float32", (1,))}, values)
    path = next((ds / "data").rglob("*.parquet"))
    path.write_bytes(path.read_bytes()[:50])
    with pytest.raises(CorruptDatasetError, match="--repair"):
        add_features(ds, NEW, values)
