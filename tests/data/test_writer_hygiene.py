"""What the writer leaves on disk: no lock file, nothing before the first episode, a dataset card,
and per-episode provenance in the episodes metadata (read back from old datasets without it)."""

from __future__ import annotations

import errno
import fcntl
import json
import os
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from vcage.data import DatasetReader, DatasetWriter, Feature, layout
from vcage.data import video as video_mod
from vcage.data.verify import verify
from vcage.errors import DatasetError

FPS = 10
CAMS = ("observation.images.front", "observation.images.wrist")
FEATURES = {"observation.state": Feature("float32", (3,), names=["x", "y", "z"]),
            "action": Feature("float32", (2,), names=["left", "right"]),
            "observation.flag": Feature("bool", (1,))}
EPISODES = "meta/episodes/chunk-000/file-000.parquet"


def open_writer(root: Path) -> DatasetWriter:
    return DatasetWriter(root, fps=FPS, features=FEATURES, cameras=dict.fromkeys(CAMS, (16, 16)),
                         robot_type="panda", config={"seed": 3})


def add(w: DatasetWriter, length: int = 4, task: str = "press the bell", extras: dict | None = None) -> int:
    frames = {"observation.state": np.ones((length, 3), np.float32),
              "action": np.zeros((length, 2), np.float32), "observation.flag": np.ones((length, 1), bool)}
    videos = {key: np.full((length, 16, 16, 3), 90, np.uint8) for key in CAMS}
    return w.add_episode(frames, videos, task=task, extras=extras)


def files(root: Path) -> list[str]:
    return sorted(p.relative_to(root).as_posix() for p in root.rglob("*") if p.is_file())


def locked(root: Path) -> bool:
    fd = os.open(root, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as exc:
        assert exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN)
        return True
    finally:
        os.close(fd)
    return False


def test_the_lock_is_the_directory_itself_and_no_lock_file_is_left(tmp_path: Path,
                                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    root = tmp_path / "ds"
    seen: list[list[str]] = []
    real = video_mod.encode_video

    def spy(path: Path, frames: np.ndarray, fps: int, encoder: str) -> None:
        seen.append(files(root))  # what exists while an episode is being written
        real(path, frames, fps, encoder)

    with open_writer(root) as w:
        assert files(root) == [] and locked(root)
        with pytest.raises(DatasetError, match="another writer"):
            open_writer(root)
        monkeypatch.setattr(video_mod, "encode_video", spy)
        add(w)
        monkeypatch.undo()
        assert not any("lock" in f for f in files(root))
    assert seen and all(not any("lock" in f or f.startswith("meta/") for f in s) for s in seen)
    assert not locked(root) and not any("lock" in f for f in files(root))
    assert verify(root).ok


def test_a_legacy_lock_file_is_removed_on_reopen(tmp_path: Path) -> None:
    root = tmp_path / "ds"
    with open_writer(root) as w:
        add(w)
    (root / layout.LEGACY_LOCK_PATH).write_text("")
    with open_writer(root) as w:
        assert not (root / layout.LEGACY_LOCK_PATH).exists()
        add(w)
    assert DatasetReader(root).num_episodes == 2


def test_a_writer_without_episodes_leaves_the_directory_as_it_found_it(tmp_path: Path) -> None:
    nested = tmp_path / "a" / "b" / "ds"
    with open_writer(nested):
        assert nested.is_dir() and files(nested) == []
    assert not (tmp_path / "a").exists()  # absent before: absent after, parents included

    empty = tmp_path / "empty"
    empty.mkdir()
    open_writer(empty).close()
    assert empty.is_dir() and list(empty.iterdir()) == []  # empty before: empty after


def test_a_failed_first_episode_leaves_nothing_behind(tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    root = tmp_path / "ds"

    def broken(*args: object, **kwargs: object) -> None:
        raise OSError("disk full")

    with open_writer(root) as w:
        monkeypatch.setattr(w, "_write_info", broken)
        with pytest.raises(OSError, match="disk full"):
            add(w)
        assert files(root) == []
    assert not root.exists()
    with open_writer(root) as w:  # the corrected command is not blocked by a half dataset
        monkeypatch.undo()
        assert add(w) == 0
    assert verify(root).ok


def test_nothing_is_persisted_until_the_first_commit(tmp_path: Path) -> None:
    root = tmp_path / "ds"
    with open_writer(root) as w:
        assert files(root) == []
        add(w)
        assert {"meta/info.json", "meta/vcage.json", "README.md"} <= set(files(root))
    marker = json.loads((root / "meta/vcage.json").read_text())
    assert marker["config"] == {"seed": 3}
    assert marker["info"]["features"]["action"]["names"] == ["left", "right"]


def test_the_dataset_card_names_every_feature_and_file(tmp_path: Path) -> None:
    root = tmp_path / "ds"
    with open_writer(root) as w:
        add(w, 4, "press the bell")
        add(w, 5, "open | the drawer")
    card = (root / "README.md").read_text()
    info = json.loads((root / "meta/info.json").read_text())
    for key in info["features"]:
        assert f"| `{key}` |" in card
    assert "`x`, `y`, `z`" in card and "`left`, `right`" in card and "| bool | 1 |" in card
    for key in CAMS:
        assert f"| `{key}` | 16 × 16 |" in card
    assert "- episodes: 2" in card and "- frames: 9 at 10 fps" in card and "vcage" in card
    assert "press the bell" in card and "open \\| the drawer" in card
    for rel in (layout.VCAGE_PATH, layout.ATTEMPTS_LOG, layout.RUNS_LOG, "extras/episode_NNNNNN.json",
                "extras/episode_NNNNNN_states.npz", layout.INFO_PATH, layout.TASKS_PATH):
        assert f"`{rel}`" in card
    with open_writer(root) as w:  # rewritten at each commit
        add(w, 3, "press the bell")
    assert "- episodes: 3" in (root / "README.md").read_text()
    assert not [f for f in files(root) if ".tmp-" in f]


def test_the_episodes_metadata_carries_provenance(tmp_path: Path) -> None:
    root = tmp_path / "ds"
    with open_writer(root) as w:
        add(w, extras={"seed": 41, "attempt": 2, "oracle_success": True, "plan": []})
        add(w)  # no extras: nulls
        add(w, extras={"seed": 43, "attempt": 0, "oracle_success": False})
    table = pq.read_table(root / EPISODES)
    schema = table.schema
    assert schema.field("vcage/seed").type == pa.int64() and schema.field("vcage/attempt").type == pa.int64()
    assert schema.field("vcage/oracle_success").type == pa.bool_()
    assert table.column("vcage/seed").to_pylist() == [41, None, 43]
    assert table.column("vcage/attempt").to_pylist() == [2, None, 0]
    assert table.column("vcage/oracle_success").to_pylist() == [True, None, False]
    assert DatasetReader(root).episode_meta(0)["vcage/seed"] == 41


def test_a_dataset_without_provenance_columns_is_read_and_appended(tmp_path: Path) -> None:
    root = tmp_path / "ds"
    with open_writer(root) as w:
        add(w, extras={"seed": 1})
        add(w, extras={"seed": 2})
    old = pq.read_table(root / EPISODES)
    pq.write_table(old.drop_columns([c for c in old.column_names if c.startswith("vcage/")]), root / EPISODES)
    marker = json.loads((root / "meta/vcage.json").read_text())  # schema 1: rows without digests
    (root / "meta/vcage.json").write_text(json.dumps({k: v for k, v in marker.items() if k != "schema"}))
    reader = DatasetReader(root)
    assert reader.num_episodes == 2 and "vcage/seed" not in reader.episode_meta(1)
    assert verify(root).ok
    with open_writer(root) as w:
        add(w, extras={"seed": 3, "attempt": 1, "oracle_success": True})
    table = pq.read_table(root / EPISODES)
    assert table.column("vcage/seed").to_pylist() == [None, None, 3]
    assert table.schema.field("vcage/oracle_success").type == pa.bool_()
    assert DatasetReader(root).episode(2).length == 4
