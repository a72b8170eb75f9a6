"""Many episodes per data and video file, as LeRobot packs them: files roll over at their size
limits, shared files survive failures, crashes and repairs, and every episode reads back exactly."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from data.content import contents_by_episode
from vcage.data import DatasetReader, DatasetWriter, Feature
from vcage.data import video as video_mod
from vcage.data.files import backup_path
from vcage.data.repair import repair
from vcage.data.verify import check, verify

FPS = 10
CAMS = ("observation.images.front", "observation.images.wrist")
FEATURES = {"observation.state": Feature("float32", (4,)), "action": Feature("float32", (3,))}
LENGTHS = (9, 6, 11, 7, 8, 5, 10, 6)


def open_writer(root: Path, **kw: float) -> DatasetWriter:
    return DatasetWriter(root, fps=FPS, features=FEATURES, cameras=dict.fromkeys(CAMS, (32, 32)),
                         robot_type="panda", config={"packing": 1}, **kw)


def make(length: int, seed: int) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    rng = np.random.default_rng(seed)
    frames = {"observation.state": rng.normal(size=(length, 4)).astype(np.float32),
              "action": rng.normal(size=(length, 3)).astype(np.float32)}
    videos = {key: rng.integers(0, 256, size=(length, 32, 32, 3), dtype=np.uint8) for key in CAMS}
    return frames, videos


def add(w: DatasetWriter, seed: int) -> int:
    frames, videos = make(LENGTHS[seed], seed)
    return w.add_episode(frames, videos, task=f"task {seed % 3}", extras={"seed": seed},
                         arrays={"states": np.zeros((LENGTHS[seed], 2))})


def rows(root: Path) -> list[dict]:
    paths = sorted((root / "meta/episodes").rglob("*.parquet"))
    return [r for p in paths for r in pq.read_table(p).to_pylist()]


def files(root: Path, sub: str) -> list[Path]:
    return sorted(p for p in (root / sub).rglob("*") if p.is_file() and not p.name.startswith("."))


@pytest.fixture(scope="module")
def one_size(tmp_path_factory: pytest.TempPathFactory) -> float:
    """The size in MB of one episode's largest file (a video): limits are set in multiples of it."""
    root = tmp_path_factory.mktemp("one") / "ds"
    with open_writer(root) as w:
        add(w, 0)
    return max(p.stat().st_size for p in files(root, "videos")) / 2**20


@pytest.fixture(scope="module")
def rolled(tmp_path_factory: pytest.TempPathFactory, one_size: float) -> Path:
    """Eight episodes in files of about three episodes' videos each, chunks of two files."""
    root = tmp_path_factory.mktemp("rolled") / "ds"
    with DatasetWriter(root, fps=FPS, features=FEATURES, cameras=dict.fromkeys(CAMS, (32, 32)),
                       robot_type="panda", config={"packing": 1}, chunks_size=2,
                       video_files_size_in_mb=3.2 * one_size) as w:
        for seed in range(len(LENGTHS)):
            add(w, seed)
    return root


@pytest.fixture()
def packed(tmp_path: Path) -> Path:
    """Four episodes in one data file and one video per camera (LeRobot's default limits)."""
    root = tmp_path / "ds"
    with open_writer(root) as w:
        for seed in range(4):
            add(w, seed)
    return root


def test_files_roll_over_at_their_size_limit_and_stay_aligned(rolled: Path, one_size: float) -> None:
    meta = rows(rolled)
    positions = [(r["data/chunk_index"], r["data/file_index"]) for r in meta]
    assert positions == sorted(positions) and len(set(positions)) > 1  # more than one file
    counts = {p: positions.count(p) for p in positions}
    assert max(counts.values()) >= 2  # and files shared by several episodes
    distinct = sorted(counts)
    assert distinct[0] == (0, 0) and all(b in ((a[0], a[1] + 1), (a[0] + 1, 0)) for a, b in zip(
        distinct, distinct[1:], strict=False))  # consecutive positions; a chunk holds two files
    assert all(file < 2 for _, file in distinct)
    limit = 3.2 * one_size * 2**20
    for key in CAMS:
        assert [(r[f"videos/{key}/chunk_index"], r[f"videos/{key}/file_index"]) for r in meta] == positions
        for path in files(rolled, f"videos/{key}"):
            where = [f"chunk-{r['data/chunk_index']:03d}/file-{r['data/file_index']:03d}" for r in meta]
            alone = sum(1 for w in where if w in path.as_posix()) == 1
            assert path.stat().st_size <= limit or alone
    info = json.loads((rolled / "meta/info.json").read_text())
    assert info["video_files_size_in_mb"] == pytest.approx(3.2 * one_size)
    assert verify(rolled).ok


def test_every_episode_reads_back_exactly_from_shared_files(rolled: Path, tmp_path: Path) -> None:
    reader = DatasetReader(rolled)
    encoder = json.loads((rolled / "meta/info.json").read_text())["features"][CAMS[0]]["info"]["video.codec"]
    for seed, length in enumerate(LENGTHS):
        frames, videos = make(length, seed)
        episode = reader.episode(seed)
        np.testing.assert_array_equal(episode.frames["action"], frames["action"])
        np.testing.assert_array_equal(episode.frames["frame_index"], np.arange(length))
        for key in CAMS:  # packets copied, never re-encoded: the same pixels as the episode alone
            alone = tmp_path / f"{seed}-{key}.mp4"
            video_mod.encode_video(alone, videos[key], FPS, video_mod.choose_encoder())
            assert video_mod.codec_name(video_mod.choose_encoder()) == encoder
            np.testing.assert_array_equal(reader.video(seed, key), video_mod.decode_video(alone)[0])


def test_an_append_joins_the_last_file_of_a_dataset_written_a_file_per_episode(tmp_path: Path) -> None:
    """Datasets of older vcage versions have a file per episode and record LeRobot's limits."""
    root = tmp_path / "ds"
    with open_writer(root, data_files_size_in_mb=1e-6, video_files_size_in_mb=1e-6) as w:
        add(w, 0)
        add(w, 1)
    info = json.loads((root / "meta/info.json").read_text())
    (root / "meta/info.json").write_text(json.dumps(info | {"data_files_size_in_mb": 100,
                                                            "video_files_size_in_mb": 200}))
    with open_writer(root) as w:
        add(w, 2)
    assert [(r["data/file_index"], r[f"videos/{CAMS[0]}/from_timestamp"]) for r in rows(root)] == [
        (0, 0.0), (1, 0.0), (1, LENGTHS[1] / FPS)]
    assert verify(root).ok
    np.testing.assert_array_equal(DatasetReader(root).episode(2).frames["action"],
                                  make(LENGTHS[2], 2)[0]["action"])


def test_damage_to_a_shared_file_costs_every_episode_in_it(packed: Path) -> None:
    data = packed / "data/chunk-000/file-000.parquet"
    data.write_bytes(data.read_bytes()[:-100])
    for report in (check(packed), verify(packed)):
        assert report.damaged == (0, 1, 2, 3)
        assert {p.path for p in report.problems} == {"data/chunk-000/file-000.parquet"}
    result = repair(packed)
    assert result.kept == 0 and result.after.ok and not files(packed, "data")


def test_repair_keeps_every_intact_episode_of_shared_files(packed: Path) -> None:
    """The damaged episode's part of each shared file goes; the episodes before and after it stay,
    their packets copied (not re-encoded), the one after it renumbered."""
    before = contents_by_episode(packed)
    states = packed / "extras/episode_000002_states.npz"
    states.write_bytes(states.read_bytes()[:20])
    names = ["data/chunk-000/file-000.parquet", *(f"videos/{k}/chunk-000/file-000.mp4" for k in CAMS)]
    shared = {rel: (packed / rel).read_bytes() for rel in names}
    result = repair(packed)
    assert (result.kept, result.dropped, result.renumbered) == (3, (2,), {3: 2}) and result.after.ok
    assert "data/chunk-000/file-000.parquet" in result.rewritten
    kept_frames = LENGTHS[0] + LENGTHS[1] + LENGTHS[3]
    assert pq.read_metadata(packed / "data/chunk-000/file-000.parquet").num_rows == kept_frames
    assert result.quarantine is not None  # the shared files as they were, the dropped episode's part too
    assert {rel: (packed / result.quarantine / rel).read_bytes() for rel in shared} == shared
    for key in CAMS:
        frames, _ = video_mod.decode_video(packed / f"videos/{key}/chunk-000/file-000.mp4")
        assert len(frames) == kept_frames
    assert contents_by_episode(packed) == [before[0], before[1], before[3]]
    with open_writer(packed) as w:  # appending joins the rewritten files again
        assert add(w, 2) == 3
    assert verify(packed).ok and rows(packed)[3]["data/file_index"] == 0


def test_repair_rebuilds_lost_rows_of_episodes_in_shared_files(rolled: Path, tmp_path: Path) -> None:
    root = tmp_path / "ds"
    shutil.copytree(rolled, root)
    original = rows(root)
    for path in (root / "meta/episodes").rglob("*.parquet"):
        path.unlink()
    result = repair(root)
    assert result.kept == len(LENGTHS) and result.after.ok and result.rebuilt == tuple(range(len(LENGTHS)))
    rebuilt = rows(root)
    located = [k for k in original[0] if "/chunk_index" in k or "/file_index" in k or "timestamp" in k
               or k.startswith("dataset_")]
    assert [{k: r[k] for k in located} for r in rebuilt] == [{k: r[k] for k in located} for r in original]


def test_a_backup_of_a_committed_episode_is_dropped_not_restored(packed: Path) -> None:
    """A crash after the commit but before the backups were deleted: the new bytes stay."""
    data = packed / "data/chunk-000/file-000.parquet"
    backup_path(data, 3).write_bytes(b"the file before episode 3, which committed")
    data_bytes = data.read_bytes()
    with open_writer(packed) as w:
        assert w.num_episodes == 4
    assert data.read_bytes() == data_bytes and not backup_path(data, 3).exists()
    assert verify(packed).ok


def _crash_appending_episode_4(packed: Path) -> dict[Path, bytes]:
    """A crash after episode 4 replaced the shared files (backups of their committed bytes beside
    them), before its commit; the shared files' committed bytes."""
    committed = {p: p.read_bytes() for p in files(packed, "data") + files(packed, "videos")}
    for path in committed:
        shutil.copy(path, backup_path(path, 4))
    with open_writer(packed) as w:  # a writer that appends for real, then a crash replayed by hand
        add(w, 4)
    for path, data in committed.items():
        backup_path(path, 4).write_bytes(data)
    info = json.loads((packed / "meta/info.json").read_text())
    (packed / "meta/info.json").write_text(json.dumps(info | {"total_episodes": 4,
                                                              "total_frames": sum(LENGTHS[:4])}))
    return committed


def test_an_interrupted_append_is_undone_when_the_dataset_is_reopened(packed: Path) -> None:
    """A crash after episode 4 replaced the shared files, before its commit: the files go back."""
    committed = _crash_appending_episode_4(packed)
    assert pq.read_metadata(packed / "data/chunk-000/file-000.parquet").num_rows == sum(LENGTHS[:5])
    report = verify(packed)  # checked in the backups: no episode is damaged, but a reader sees episode 4
    assert not report.ok and report.damaged == () and "interrupted" in report.summary()
    with open_writer(packed) as w:
        assert w.num_episodes == 4
        assert {p: p.read_bytes() for p in committed} == committed
    assert verify(packed).ok and not list(packed.rglob(".*keep-*"))


def test_repair_after_a_crash_puts_back_the_committed_bytes_and_says_so(packed: Path) -> None:
    """Found on 2026-12-05: after a crash, verify said clean while a plain pyarrow reader saw the
    uncommitted episode, and verify --repair said "nothing to repair" while it restored three files,
    leaving a temporary file behind."""
    committed = _crash_appending_episode_4(packed)
    scratch = packed / "data/chunk-000/.file-000.parquet.tmp-1-abcd"
    scratch.write_bytes(b"partial")
    data = packed / "data/chunk-000/file-000.parquet"
    assert pq.read_table(data).num_rows == sum(LENGTHS[:5])  # what a plain reader sees
    report = verify(packed)
    assert not report.ok and report.damaged == ()
    assert {p.path for p in report.problems} >= {str(p.relative_to(packed)) for p in committed}
    result = repair(packed)
    assert result.restored and result.after.ok and "nothing to repair" not in result.summary()
    assert "put back the committed bytes" in result.summary() and result.kept == 4
    assert {p: p.read_bytes() for p in committed} == committed and not scratch.exists()
    assert pq.read_table(data).num_rows == sum(LENGTHS[:4])
    assert not list(packed.rglob(".*keep-*")) and not list(packed.rglob(".*tmp-*"))
