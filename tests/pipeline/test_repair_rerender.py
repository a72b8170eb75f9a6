"""A generated dataset whose videos are damaged: ``vcage verify --repair`` renders them again from
the simulator states each episode stores and keeps the episodes, but only where the encoded frames
come out identical to those written; otherwise the episode is dropped, saying why."""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from data.content import contents_by_episode
from vcage.cli import app
from vcage.config import RenderConfig
from vcage.data.repair import repair
from vcage.data.verify import verify
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.generate import generate
from vcage.pipeline.rerender import render_from_states
from vcage.scene.instantiate import SceneConfig

CFG = GenerateConfig(scene=SceneConfig(clutter=1),
                     render=RenderConfig(size=(64, 64), cameras=("front", "panda/wrist")), critic=None,
                     seed=11)
VIDEO = "videos/observation.images.front/chunk-000/file-000.mp4"
STATES_1 = "extras/episode_000001_states.npz"


@pytest.fixture(scope="module")
def made(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("rerender") / "ds"
    assert generate("press the bell", 3, out, CFG).dataset_episodes == 3
    return out


@pytest.fixture()
def ds(made: Path, tmp_path: Path) -> Path:
    shutil.copytree(made, tmp_path / "ds")
    return tmp_path / "ds"


def truncate(path: Path) -> None:
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])


def test_a_truncated_shared_video_is_rendered_again_and_every_episode_kept(ds: Path, made: Path) -> None:
    """Found on 2026-12-05: one truncated shared mp4 cost every episode in it."""
    truncate(ds / VIDEO)
    assert verify(ds).damaged == (0, 1, 2)
    result = CliRunner().invoke(app, ["verify", str(ds), "--repair"])
    assert result.exit_code == 0, result.output
    assert "rendered the videos of 0, 1, 2 again" in " ".join(result.output.split())
    assert verify(ds).ok
    assert contents_by_episode(ds) == contents_by_episode(made)


def test_an_episode_whose_states_are_damaged_too_is_dropped_the_others_rendered_again(ds: Path,
                                                                                       made: Path) -> None:
    truncate(ds / VIDEO)
    truncate(ds / STATES_1)
    result = repair(ds, render=render_from_states)
    assert (result.kept, result.dropped, result.rerendered, result.renumbered) == (2, (1,), (0, 2), {2: 1})
    assert result.after.ok
    original = contents_by_episode(made)
    assert contents_by_episode(ds) == [original[0], original[2]]


def test_frames_that_do_not_reproduce_those_written_are_not_kept(ds: Path) -> None:
    def off_by_one(extras: dict[str, Any], states: np.ndarray) -> dict[str, np.ndarray]:
        return {key: frames ^ np.uint8(1) for key, frames in render_from_states(extras, states).items()}

    truncate(ds / VIDEO)
    result = repair(ds, render=off_by_one)
    assert (result.kept, result.dropped, result.rerendered) == (0, (0, 1, 2), ())
    assert all("differ from those written" in result.reasons[i][-1] for i in range(3))
    assert result.after.ok
