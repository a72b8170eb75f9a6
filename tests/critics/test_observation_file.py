"""A stored observation reads back as it was written: every array with its dtype and values, the
subtask, the labels and the oracle; the critic's verdict on it is the same; a file that is not one
is refused with a typed error, and a failed write leaves nothing behind."""

from __future__ import annotations

import zipfile
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from critics.recipes import faulted, observed
from vcage.critics.image import ImageCritic
from vcage.critics.observation_file import FORMAT, load_observation, save_observation
from vcage.errors import DatasetError


def test_an_observation_reads_back_as_it_was_written(tmp_path: Path) -> None:
    case = observed(faulted("pressed", "press_light", 0))
    obs = replace(case.obs, oracle={"pressed(bell)": False})
    save_observation(tmp_path / "x.npz", obs, {"note": "a light press"})
    again, extra = load_observation(tmp_path / "x.npz")
    assert extra == {"note": "a light press"}
    assert (again.subtask, again.labels, again.types, again.oracle) == (obs.subtask, obs.labels, obs.types,
                                                                         obs.oracle)
    for moment in ("before", "during", "after"):
        views, back = getattr(obs, moment), getattr(again, moment)
        assert views.keys() == back.keys() and views
        for camera, view in views.items():
            other = back[camera]
            assert (other.pixel_size, other.robot_base) == (view.pixel_size, view.robot_base)
            for name in ("rgb", "segmentation", "depth"):
                a, b = getattr(view, name), getattr(other, name)
                assert (a is None) == (b is None)
                if a is not None:
                    assert a.dtype == b.dtype and np.array_equal(a, b)
    critic = ImageCritic()
    assert critic.judge(again).to_dict() == critic.judge(obs).to_dict()
    assert list(tmp_path.iterdir()) == [tmp_path / "x.npz"]  # no temporary file left


def test_a_view_without_depth_stays_without_it(tmp_path: Path) -> None:
    obs = observed(faulted("pressed", "press_light", 0)).obs
    front = replace(obs.after["front"], depth=None, pixel_size=None, robot_base=None)
    save_observation(tmp_path / "x.npz", replace(obs, after={**obs.after, "front": front}))
    again, _ = load_observation(tmp_path / "x.npz")
    back = again.after["front"]
    assert (back.depth, back.pixel_size, back.robot_base) == (None, None, None)


def test_a_file_that_is_not_an_observation_is_refused(tmp_path: Path) -> None:
    junk = tmp_path / "junk.npz"
    junk.write_bytes(b"not an archive")
    with pytest.raises(DatasetError, match="not a stored observation"):
        load_observation(junk)
    with pytest.raises(DatasetError, match="not a stored observation"):
        load_observation(tmp_path / "missing.npz")
    arrays = tmp_path / "arrays.npz"
    np.savez(arrays, a=np.zeros(3))  # an archive, but no meta
    with pytest.raises(DatasetError, match="not a stored observation"):
        load_observation(arrays)


def test_a_file_of_another_format_is_refused(tmp_path: Path) -> None:
    obs = observed(faulted("pressed", "press_light", 0)).obs
    path = tmp_path / "x.npz"
    save_observation(path, obs)
    with zipfile.ZipFile(path) as z:
        members = {name: z.read(name) for name in z.namelist()}
    with np.load(path) as archive:
        meta = archive["meta"].tobytes().decode().replace(f'"format": {FORMAT}', '"format": 99')
    arrays = {name[:-4]: np.load(path)[name[:-4]] for name in members if name != "meta.npy"}
    np.savez(path, meta=np.frombuffer(meta.encode(), dtype=np.uint8), **arrays)
    with pytest.raises(DatasetError, match="format 99"):
        load_observation(path)


def test_a_write_that_fails_leaves_the_old_file_and_no_part(tmp_path: Path) -> None:
    obs = observed(faulted("pressed", "press_light", 0)).obs
    path = tmp_path / "x.npz"
    save_observation(path, obs, {"first": True})
    with pytest.raises(TypeError):
        save_observation(path, obs, {"not json": object()})
    unpicklable = np.array([lambda: None], dtype=object)  # fails inside the archive, once it is open
    broken = replace(obs, after={**obs.after, "top": replace(obs.after["top"], rgb=unpicklable)})
    with pytest.raises(ValueError, match="allow_pickle"):
        save_observation(path, broken)
    assert load_observation(path)[1] == {"first": True}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.npz"]
