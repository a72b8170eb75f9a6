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
from vcage.critics.base import Observation, View
from vcage.critics.image import ImageCritic
from vcage.critics.observation_file import FORMAT, load_observation, save_observation
from vcage.errors import DatasetError
from vcage.planning.goals import press


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


def test_arrays_keep_their_dtypes_and_values(tmp_path: Path) -> None:
    """Built here, not read from a stored file: what is written is known independently of the reader."""
    rng = np.random.default_rng(0)
    view = View(rgb=rng.integers(0, 256, (6, 8, 3), dtype=np.uint8),
                segmentation=rng.integers(-2, 3, (6, 8)).astype(np.int32),
                depth=rng.random((6, 8)).astype(np.float32), pixel_size=0.1 / 3, robot_base=(-12.5, 4.0))
    deep = replace(view, depth=rng.random((6, 8)))  # float64
    obs = Observation(subtask=press("bell", "the bell is rung"), labels=("bell",),
                      before={"top": view}, during={"top": deep}, after={"top": view, "front": view},
                      types={"bell": "bell"}, oracle={"pressed(bell)": True})
    save_observation(tmp_path / "x.npz", obs)
    again, extra = load_observation(tmp_path / "x.npz")
    assert extra == {} and again.subtask == obs.subtask and again.oracle == obs.oracle
    for moment, camera in (("before", "top"), ("during", "top"), ("after", "front")):
        a, b = getattr(obs, moment)[camera], getattr(again, moment)[camera]
        for name in ("rgb", "segmentation", "depth"):
            x, y = getattr(a, name), getattr(b, name)
            assert x.dtype == y.dtype and np.array_equal(x, y), (moment, name)
        assert (b.pixel_size, b.robot_base) == (0.1 / 3, (-12.5, 4.0))


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
