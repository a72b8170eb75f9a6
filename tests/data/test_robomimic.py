"""robomimic HDF5 export of a generated dataset, read back with h5py."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

from vcage.config import RenderConfig
from vcage.data import DatasetReader
from vcage.data.robomimic import export_robomimic, obs_key
from vcage.errors import DatasetError
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.generate import generate
from vcage.scene.instantiate import SceneConfig


@pytest.fixture(scope="module")
def dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("robomimic") / "ds"
    cfg = GenerateConfig(scene=SceneConfig(clutter=1), render=RenderConfig(size=(64, 64)))
    generate("press the bell", 2, out, cfg)
    return out


def test_export_matches_the_dataset(dataset: Path, tmp_path: Path) -> None:
    summary = export_robomimic(dataset, tmp_path / "demos.hdf5", valid_fraction=0.5, seed=3)
    reader = DatasetReader(dataset)
    assert (summary.demos, summary.train, summary.valid) == (2, 1, 1)
    with h5py.File(summary.path, "r") as f:
        masks = [sorted(x.decode() for x in f["mask"][split][()]) for split in ("train", "valid")]
        assert sorted(masks[0] + masks[1]) == ["demo_0", "demo_1"]
        total = 0
        for k in range(2):
            ep, demo = reader.episode(k), f["data"][f"demo_{k}"]
            n = int(demo.attrs["num_samples"])
            total += n
            assert n == ep.length and demo.attrs["seed"] == ep.extras["seed"]
            np.testing.assert_array_equal(demo["actions"][()], ep.frames["action"])
            np.testing.assert_array_equal(demo["obs"]["state"][()], ep.frames["observation.state"])
            np.testing.assert_array_equal(demo["obs"]["front_image"][()],
                                          reader.video(k, "observation.images.front"))
            np.testing.assert_array_equal(demo["states"][()], ep.arrays["states"])
            assert demo["dones"][-1] == 1 and demo["dones"][()].sum() == 1
            assert demo["rewards"][-1] == 1.0  # the oracle confirmed the episode
        assert f["data"].attrs["total"] == total == summary.frames


def test_export_refuses_to_clobber_and_bad_input(dataset: Path, tmp_path: Path) -> None:
    target = tmp_path / "demos.hdf5"
    target.write_bytes(b"keep me")
    with pytest.raises(DatasetError, match="overwrite"):
        export_robomimic(dataset, target)
    assert target.read_bytes() == b"keep me"
    with pytest.raises(DatasetError, match="valid_fraction"):
        export_robomimic(dataset, tmp_path / "x.hdf5", valid_fraction=1.0)
    with pytest.raises(DatasetError, match="missing"):
        export_robomimic(tmp_path / "not-a-dataset", tmp_path / "y.hdf5")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["demos.hdf5"]  # no partial files left


def test_obs_keys() -> None:
    assert obs_key("observation.state") == "state"
    assert obs_key("observation.ee_pose") == "ee_pose"
    assert obs_key("observation.images.wrist") == "wrist_image"
