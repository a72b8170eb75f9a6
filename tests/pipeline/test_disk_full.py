"""A disk that fills during generate: found on 2026-12-05 to end in a traceback (exit 1). The run ends
with a typed error saying what the dataset holds and how to continue, and the committed episodes
are intact. The disk is a real one: a tmpfs of 600 kB (the test needs root, as CI runs)."""

from __future__ import annotations

import re
import shutil
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest
from typer.testing import CliRunner

from vcage.cli import app
from vcage.data import DatasetReader
from vcage.data.verify import verify


@pytest.fixture()
def small_disk(tmp_path: Path) -> Iterator[Path]:
    mount = tmp_path / "disk"
    mount.mkdir()
    made = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=600k", "tmpfs", str(mount)],
                          capture_output=True, check=False)
    if made.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here ({made.stderr.decode().strip()}); CI runs as root")
    try:
        yield mount
    finally:
        subprocess.run(["umount", str(mount)], check=False)


def test_a_disk_that_fills_ends_the_run_with_what_it_holds(small_disk: Path, tmp_path: Path) -> None:
    out = small_disk / "ds"
    result = CliRunner().invoke(app, ["generate", "press the bell", "--episodes", "40", "--out", str(out),
                                      "--critic", "oracle", "--clutter", "0", "--size", "64", "--cameras",
                                      "front"])
    said = " ".join(result.output.split())
    assert result.exit_code == 2, (said, result.exception)
    assert "no space left on the device" in said and "--total" in said, said
    held = int(re.search(r"holds (\d+) committed episodes, intact", said).group(1))  # type: ignore[union-attr]
    assert held >= 1
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)  # off the full disk, as a user would check it
    assert verify(copy).without_interrupted().ok and DatasetReader(copy).num_episodes == held


def test_the_writer_says_what_it_kept_when_the_disk_fills(small_disk: Path) -> None:
    import numpy as np

    from vcage.data import DatasetWriter, Feature
    from vcage.errors import DatasetError

    cam = "observation.images.front"
    rng = np.random.default_rng(0)
    with DatasetWriter(small_disk / "w", fps=10, features={"action": Feature("float32", (2,))},
                       cameras={cam: (64, 64)}, config={"disk": 1}) as w:
        with pytest.raises(DatasetError, match=r"no space left .* holds (\d+) committed episodes, intact"):
            for _ in range(100):  # noise does not compress: the disk fills within a few episodes
                w.add_episode({"action": np.zeros((20, 2), np.float32)},
                              {cam: rng.integers(0, 256, (20, 64, 64, 3), dtype=np.uint8)}, task="t",
                              arrays={"states": rng.normal(size=(20, 50))})
        kept = w.num_episodes
    assert kept >= 1 and DatasetReader(small_disk / "w").num_episodes == kept
