"""LeRobot v3 writer/reader on real files: layout, round trip, append, refusal, atomicity, corruption."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.compute
import pyarrow.parquet as pq
import pytest

from vcage.data import DatasetReader, DatasetWriter, Feature
from vcage.data import video as video_mod
from vcage.data.verify import verify
from vcage.errors import DatasetError

FPS = 20
SIZE = (64, 64)
CAMS = ("observation.images.front", "observation.images.wrist")
STANDARD = {"timestamp", "frame_index", "episode_index", "index", "task_index"}
FEATURES = {"observation.state": Feature("float32", (9,), names=[f"q{i}" for i in range(9)]),
            "action": Feature("float32", (8,))}
CONFIG: dict[str, Any] = {"task": "mouse_on_pad", "seed": 7, "critic": {"name": "image", "votes": 1}}


def writer(root: Path, config: dict[str, Any] | None = None, **kw: Any) -> DatasetWriter:
    args: dict[str, Any] = {"fps": FPS, "features": FEATURES, "cameras": dict.fromkeys(CAMS, SIZE),
                            "robot_type": "panda", "config": CONFIG if config is None else config}
    return DatasetWriter(root, **(args | kw))


def episode(length: int, seed: int) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """Random vectors and smooth moving-gradient frames (lossy codecs keep them close)."""
    rng = np.random.default_rng(seed)
    frames = {"observation.state": rng.normal(size=(length, 9)).astype(np.float32),
              "action": rng.uniform(-1, 1, size=(length, 8)).astype(np.float32)}
    yy, xx = np.mgrid[0:SIZE[0], 0:SIZE[1]]
    videos = {}
    for c, key in enumerate(CAMS):
        stack = [np.stack([(xx * 2 + 3 * t) % 256, (yy * 3 + 40 * c) % 256, np.full_like(xx, 60 + 5 * t)], -1)
                 for t in range(length)]
        videos[key] = np.asarray(stack, dtype=np.uint8)
    return frames, videos


def snapshot(root: Path) -> dict[str, tuple[int, int]]:
    return {p.relative_to(root).as_posix(): (p.stat().st_mtime_ns, p.stat().st_size)
            for p in sorted(root.rglob("*")) if p.is_file()}


def listing(root: Path) -> list[str]:
    return sorted(p.relative_to(root).as_posix() for p in root.rglob("*") if p.is_file())


@pytest.fixture()
def three(tmp_path: Path) -> tuple[Path, list[Any]]:
    """A dataset of three episodes (lengths 20, 15, 20; tasks a, b, a) and its inputs."""
    root = tmp_path / "ds"
    inputs = []
    with writer(root) as w:
        for i, (length, task) in enumerate([(20, "put the mouse on the pad"), (15, "stack the blocks"),
                                            (20, "put the mouse on the pad")]):
            frames, videos = episode(length, seed=i)
            extras = {"seed": i, "plan": ["pick", "place"], "boundaries": np.array([0, 7, length])}
            arrays = {"qpos": np.arange(length * 3, dtype=np.float64).reshape(length, 3) + i}
            assert w.add_episode(frames, videos, task=task, extras=extras, arrays=arrays) == i
            inputs.append((length, task, frames, videos, extras, arrays))
    return root, inputs


def test_layout_files_and_columns(three: tuple[Path, list[Any]]) -> None:
    root, inputs = three
    info = json.loads((root / "meta/info.json").read_text())
    assert {"codebase_version", "robot_type", "fps", "total_episodes", "total_frames", "total_tasks",
            "chunks_size", "data_files_size_in_mb", "video_files_size_in_mb", "splits", "data_path",
            "video_path", "features"} <= set(info)
    assert info["codebase_version"] == "v3.0" and info["fps"] == FPS and info["robot_type"] == "panda"
    assert (info["total_episodes"], info["total_frames"], info["total_tasks"]) == (3, 55, 2)
    assert info["splits"] == {"train": "0:3"} and info["chunks_size"] == 1000
    feats = info["features"]
    assert set(feats) == set(FEATURES) | set(CAMS) | STANDARD
    names = [f"q{i}" for i in range(9)]
    assert feats["observation.state"] == {"dtype": "float32", "shape": [9], "names": names}
    assert feats["timestamp"]["dtype"] == "float32" and feats["index"]["dtype"] == "int64"
    cam = feats[CAMS[0]]
    assert cam["dtype"] == "video" and cam["shape"] == [64, 64, 3]
    assert cam["info"]["video.codec"] in {"av1", "h264", "mpeg4"} and cam["info"]["has_audio"] is False
    assert cam["info"]["video.pix_fmt"] == "yuv420p" and cam["info"]["video.fps"] == FPS

    episodes = pq.read_table(root / "meta/episodes/chunk-000/file-000.parquet")
    required = {"episode_index", "tasks", "length", "data/chunk_index", "data/file_index",
                "dataset_from_index", "dataset_to_index", "meta/episodes/chunk_index",
                "meta/episodes/file_index"}
    for key in CAMS:
        required |= {f"videos/{key}/{c}" for c in ("chunk_index", "file_index", "from_timestamp",
                                                   "to_timestamp")}
    assert required <= set(episodes.column_names)
    rows = episodes.to_pylist()
    assert [r["length"] for r in rows] == [20, 15, 20]
    assert [r["dataset_from_index"] for r in rows] == [0, 20, 35]
    assert all(r["dataset_to_index"] - r["dataset_from_index"] == r["length"] for r in rows)

    tasks = pq.read_table(root / "meta/tasks.parquet").to_pylist()
    assert tasks == [{"task_index": 0, "task": "put the mouse on the pad"},
                     {"task_index": 1, "task": "stack the blocks"}]
    task_of = {t["task_index"]: t["task"] for t in tasks}

    # packed as LeRobot packs them: the three episodes share one data file and one mp4 per camera
    assert listing(root / "data") == ["chunk-000/file-000.parquet"]
    for key in CAMS:
        assert listing(root / "videos" / key) == ["chunk-000/file-000.mp4"]
    table = pq.read_table(root / "data/chunk-000/file-000.parquet")
    assert set(table.column_names) == set(FEATURES) | STANDARD
    assert table.schema.field("observation.state").type == pa.list_(pa.float32(), 9)
    assert table.schema.field("timestamp").type == pa.float32()
    all_index, start = [], 0
    for row, (length, task, *_rest) in zip(rows, inputs, strict=True):
        assert (row["data/chunk_index"], row["data/file_index"]) == (0, 0)
        for key in CAMS:
            assert (row[f"videos/{key}/chunk_index"], row[f"videos/{key}/file_index"]) == (0, 0)
            assert row[f"videos/{key}/from_timestamp"] == pytest.approx(start / FPS)
            assert row[f"videos/{key}/to_timestamp"] == pytest.approx((start + length) / FPS)
        mine = table.filter(pa.compute.equal(table.column("episode_index"), row["episode_index"]))
        frame_index = mine.column("frame_index").to_numpy()
        np.testing.assert_array_equal(frame_index, np.arange(length))
        np.testing.assert_allclose(mine.column("timestamp").to_numpy(), frame_index / FPS, rtol=1e-6)
        assert {task_of[t] for t in mine.column("task_index").to_pylist()} == {task} == set(row["tasks"])
        all_index += mine.column("index").to_pylist()
        start += length
    np.testing.assert_array_equal(table.column("episode_index").to_numpy(),
                                  np.repeat([0, 1, 2], [20, 15, 20]))
    for key in CAMS:  # one frame per row, in episode order
        frames, times = video_mod.decode_video(root / f"videos/{key}/chunk-000/file-000.mp4")
        assert len(frames) == 55 and np.allclose(times, np.arange(55) / FPS)
    assert all_index == list(range(55))
    assert (root / "extras/episode_000001.json").is_file()
    assert (root / "extras/episode_000001_states.npz").is_file()
    assert json.loads((root / "meta/vcage.json").read_text())["config"] == CONFIG


def test_round_trip_reader(three: tuple[Path, list[Any]]) -> None:
    root, inputs = three
    reader = DatasetReader(root)
    assert (reader.num_episodes, reader.fps, reader.total_frames) == (3, FPS, 55)
    assert reader.features == FEATURES and reader.cameras == dict.fromkeys(CAMS, SIZE)
    assert reader.tasks == ["put the mouse on the pad", "stack the blocks"] and reader.config == CONFIG
    for i, (length, task, frames, videos, _extras, arrays) in enumerate(inputs):
        ep = reader.episode(i)
        assert (ep.index, ep.task, ep.length) == (i, task, length)
        for key, value in frames.items():
            np.testing.assert_array_equal(ep.frames[key], value)
        np.testing.assert_allclose(ep.frames["timestamp"], np.arange(length) / FPS, rtol=1e-6)
        assert ep.extras == {"seed": i, "plan": ["pick", "place"], "boundaries": [0, 7, length]}
        assert set(ep.arrays) == {"qpos"}
        np.testing.assert_array_equal(ep.arrays["qpos"], arrays["qpos"])
        for key in CAMS:
            decoded = reader.video(i, key)
            assert decoded.shape == videos[key].shape and decoded.dtype == np.uint8
            assert np.abs(decoded.astype(np.int16) - videos[key]).mean() < 4.0


def test_stats(three: tuple[Path, list[Any]]) -> None:
    root, inputs = three
    stats = json.loads((root / "meta/stats.json").read_text())
    assert set(stats) == set(FEATURES) | set(CAMS) | STANDARD
    state = np.concatenate([frames["observation.state"] for _, _, frames, *_ in inputs]).astype(np.float64)
    s = stats["observation.state"]
    assert set(s) >= {"mean", "std", "min", "max"} and s["count"] == [55]
    np.testing.assert_allclose(s["mean"], state.mean(0), atol=1e-6)
    np.testing.assert_allclose(s["std"], state.std(0), atol=1e-6)
    np.testing.assert_allclose(s["min"], state.min(0))
    np.testing.assert_allclose(s["max"], state.max(0))
    np.testing.assert_allclose(stats["index"]["max"], [54])
    img = stats[CAMS[0]]
    for name in ("mean", "std", "min", "max"):
        arr = np.asarray(img[name])
        assert arr.shape == (3, 1, 1) and (arr >= 0).all() and (arr <= 1).all()
    pixels = np.concatenate([v[CAMS[0]] for *_, v, _, _ in inputs]).reshape(-1, 3) / 255.0
    np.testing.assert_allclose(np.asarray(img["mean"]).ravel(), pixels.mean(0), atol=1e-6)


def test_append_same_config_continues(three: tuple[Path, list[Any]]) -> None:
    root, inputs = three
    with writer(root, config=json.loads(json.dumps(CONFIG))) as w:
        assert w.num_episodes == 3
        frames, videos = episode(10, seed=9)
        assert w.add_episode(frames, videos, task="open the drawer") == 3
    reader = DatasetReader(root)
    assert reader.num_episodes == 4 and reader.total_frames == 65 and len(reader.tasks) == 3
    last = reader.episode(3)
    np.testing.assert_array_equal(last.frames["index"], np.arange(55, 65))
    assert last.extras == {} and last.arrays == {} and last.task == "open the drawer"
    assert reader.episode(0).extras["seed"] == 0  # earlier episodes untouched
    state = np.concatenate([f["observation.state"] for _, _, f, *_ in inputs] + [frames["observation.state"]])
    stats = json.loads((root / "meta/stats.json").read_text())["observation.state"]
    np.testing.assert_allclose(stats["std"], state.astype(np.float64).std(0), atol=1e-6)
    assert stats["count"] == [65]


@pytest.mark.parametrize("change", [
    {"config": CONFIG | {"seed": 8}},
    {"fps": 10},
    {"features": FEATURES | {"action": Feature("float32", (7,))}},
    {"cameras": {CAMS[0]: SIZE}},
    {"robot_type": "ur5"},
])
def test_different_config_refused_nothing_changed(three: tuple[Path, list[Any]],
                                                  change: dict[str, Any]) -> None:
    root, _ = three
    before = snapshot(root)
    with pytest.raises(DatasetError, match="different configuration.*another --out"):
        writer(root, **change)
    assert snapshot(root) == before


def test_different_config_message_names_the_difference(three: tuple[Path, list[Any]]) -> None:
    with pytest.raises(DatasetError, match=r"config\.seed: existing 7 != given 8"):
        writer(three[0], config=CONFIG | {"seed": 8})


def test_foreign_directory_refused(tmp_path: Path) -> None:
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(DatasetError, match="no vcage dataset"):
        writer(tmp_path)
    assert listing(tmp_path) == ["notes.txt"]
    with pytest.raises(DatasetError, match="is a file"):
        writer(tmp_path / "notes.txt")


def test_second_writer_is_locked_out(tmp_path: Path) -> None:
    with writer(tmp_path / "ds"), pytest.raises(DatasetError, match="another writer"):
        writer(tmp_path / "ds")
    writer(tmp_path / "ds").close()


def _bad_inputs() -> list[tuple[str, dict[str, Any]]]:
    frames, videos = episode(20, seed=1)
    short_action = frames | {"action": frames["action"][:19]}
    return [
        ("lengths", {"frames": short_action, "videos": videos}),
        ("shape", {"frames": frames | {"observation.state": frames["observation.state"][:, :8]},
                   "videos": videos}),
        ("video size", {"frames": frames, "videos": videos | {CAMS[0]: videos[CAMS[0]][:, :32, :32]}}),
        ("video length", {"frames": frames, "videos": videos | {CAMS[1]: videos[CAMS[1]][:5]}}),
        ("video dtype", {"frames": frames, "videos": videos | {CAMS[0]: videos[CAMS[0]].astype(np.float32)}}),
        ("missing key", {"frames": {"action": frames["action"]}, "videos": videos}),
        ("extra key", {"frames": frames | {"reward": np.zeros(20)}, "videos": videos}),
        ("empty", {"frames": {k: v[:0] for k, v in frames.items()},
                   "videos": {k: v[:0] for k, v in videos.items()}}),
        ("nan", {"frames": frames | {"action": np.full((20, 8), np.nan)}, "videos": videos}),
        ("empty task", {"frames": frames, "videos": videos, "task": ""}),
        ("extras", {"frames": frames, "videos": videos, "extras": {"x": object()}}),
    ]


@pytest.mark.parametrize(("what", "kwargs"), _bad_inputs(), ids=[name for name, _ in _bad_inputs()])
def test_invalid_episode_refused_and_nothing_written(tmp_path: Path, what: str,
                                                     kwargs: dict[str, Any]) -> None:
    root = tmp_path / "ds"
    with writer(root) as w:
        before = snapshot(root)
        with pytest.raises(DatasetError):
            w.add_episode(**({"task": "t"} | kwargs))
        assert snapshot(root) == before == {} and w.num_episodes == 0
    assert not root.exists()  # a new dataset that got no episode leaves nothing behind


def test_shape_error_names_key_and_shapes(tmp_path: Path) -> None:
    frames, videos = episode(20, seed=1)
    pattern = r"observation.state.*\(20, 8\).*\(T, 9\)"
    with writer(tmp_path / "ds") as w, pytest.raises(DatasetError, match=pattern):
        w.add_episode(frames | {"observation.state": frames["observation.state"][:, :8]}, videos, task="t")


def test_bad_construction_refused(tmp_path: Path) -> None:
    with pytest.raises(DatasetError, match="even"):
        writer(tmp_path / "a", cameras={CAMS[0]: (63, 64)})
    with pytest.raises(DatasetError, match="clash"):
        writer(tmp_path / "b", features={"index": Feature("int64", (1,))})
    with pytest.raises(DatasetError, match="dtype"):
        Feature("float16", (3,))
    with pytest.raises(DatasetError, match="names"):
        Feature("float32", (3,), names=["x", "y"])
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()


@pytest.mark.parametrize("fail_at", ["second video", "joining a video", "commit"])
def test_failed_episode_keeps_earlier_episodes(three: tuple[Path, list[Any]], fail_at: str,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    """A failure before, while and after the shared files are rewritten leaves them byte for byte."""
    root, inputs = three
    before = contents(root)
    w = writer(root)
    if fail_at == "second video":
        real = video_mod.encode_video
        calls: list[int] = []

        def flaky(path: Path, frames: np.ndarray, fps: int, encoder: str) -> None:
            calls.append(1)
            if len(calls) == 2:
                raise OSError("disk full")
            real(path, frames, fps, encoder)

        monkeypatch.setattr(video_mod, "encode_video", flaky)
    elif fail_at == "joining a video":  # the data file is already replaced by then
        real_concat = video_mod.concat_videos

        def flaky_concat(sources: list[tuple[Path, int]], out: Path, fps: int) -> None:
            real_concat(sources, out, fps)
            raise OSError("disk full")

        monkeypatch.setattr(video_mod, "concat_videos", flaky_concat)
    else:
        def broken_info(episodes: int, frames: int, tasks: int) -> None:
            raise OSError("disk full")

        monkeypatch.setattr(w, "_write_info", broken_info)
    frames, videos = episode(12, seed=5)
    with pytest.raises(OSError, match="disk full"):
        w.add_episode(frames, videos, task="a new task", extras={"seed": 5}, arrays={"s": np.zeros(3)})
    assert contents(root) == before  # the shared files put back, no stray files, no temp files
    reader = DatasetReader(root)
    assert reader.num_episodes == 3 and len(reader.tasks) == 2
    np.testing.assert_array_equal(reader.episode(2).frames["action"], inputs[2][2]["action"])
    monkeypatch.undo()
    assert w.add_episode(frames, videos, task="a new task") == 3  # the same writer goes on
    w.close()
    assert DatasetReader(root).episode(3).frames["index"][0] == 55


def contents(root: Path) -> dict[str, bytes]:
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def test_crash_leftovers_ignored_then_removed(three: tuple[Path, list[Any]]) -> None:
    """A crash after episode 3 had replaced the shared files (keeping backups of the committed
    bytes) and started files of its own, but before the commit (info.json)."""
    root, _ = three
    committed = contents(root)
    shared = [root / "data/chunk-000/file-000.parquet",
              *(root / "videos" / key / "chunk-000/file-000.mp4" for key in CAMS)]
    for path in shared:  # what the writer does before it replaces a shared file
        path.with_name(f".{path.name}.keep-000003").hardlink_to(path)
        path.unlink()
        path.write_bytes(b"the shared file with episode 3 appended")
    (root / "data/chunk-000/file-001.parquet").write_bytes(b"a file episode 3 started")
    (root / "data/chunk-000/.file-004.parquet.tmp-1-abcd").write_bytes(b"partial")
    (root / "extras/episode_000003.json").write_text("{}")
    episodes_file = root / "meta/episodes/chunk-000/file-000.parquet"
    rows = pq.read_table(episodes_file).to_pylist()
    pq.write_table(pa.Table.from_pylist(rows + [rows[-1] | {"episode_index": 3}]), episodes_file)
    # the committed bytes are checked, in the backups: no episode is damaged; but a plain reader of the
    # shared files and of the episodes' rows would see the interrupted episode, and verify says so
    report = verify(root)
    assert not report.ok and report.damaged == (), report.summary()
    assert all("interrupted" in p.what for p in report.problems) and len(report.problems) == 4
    with writer(root) as w:
        after = contents(root)
        assert set(after) == set(committed) and all(after[k] == committed[k] for k in after
                                                     if not k.startswith("meta/episodes"))
        frames, videos = episode(8, seed=3)
        assert w.add_episode(frames, videos, task="stack the blocks") == 3
    reader = DatasetReader(root)
    assert reader.num_episodes == 4 and reader.episode(3).length == 8 and len(reader.tasks) == 2
    assert verify(root).ok and not list(root.rglob(".*keep-*"))


def _corrupt_cases() -> list[tuple[str, str]]:
    return [("missing info", "info.json"), ("bad info", "info.json"), ("missing data", "file-000.parquet"),
            ("missing video", "file-000.mp4"), ("count mismatch", "info.json"),
            ("bad episodes", "meta/episodes/chunk-000/file-000.parquet"), ("missing tasks", "tasks.parquet")]


@pytest.mark.parametrize(("case", "named"), _corrupt_cases(), ids=[c for c, _ in _corrupt_cases()])
def test_corrupt_dataset_raises_naming_the_file(three: tuple[Path, list[Any]], case: str, named: str) -> None:
    root, _ = three
    info_path = root / "meta/info.json"
    if case == "missing info":
        info_path.unlink()
    elif case == "bad info":
        info_path.write_text("{not json")
    elif case == "missing data":
        (root / "data/chunk-000/file-000.parquet").unlink()
    elif case == "missing video":
        (root / "videos" / CAMS[1] / "chunk-000/file-000.mp4").unlink()
    elif case == "count mismatch":
        info_path.write_text(json.dumps(json.loads(info_path.read_text()) | {"total_episodes": 4}))
    elif case == "bad episodes":
        (root / named).write_bytes(b"PAR1 garbage")
    else:
        (root / "meta/tasks.parquet").unlink()
    with pytest.raises(DatasetError, match=named):
        DatasetReader(root)


def test_unreadable_episode_files_raise_on_read(three: tuple[Path, list[Any]]) -> None:
    root, _ = three
    (root / "videos" / CAMS[0] / "chunk-000/file-000.mp4").write_bytes(b"not a video")
    reader = DatasetReader(root)
    with pytest.raises(DatasetError, match="file-000.mp4"):
        reader.video(2, CAMS[0])
    assert reader.episode(0).length == 20 and len(reader.video(1, CAMS[1])) == 15
    (root / "data/chunk-000/file-000.parquet").write_bytes(b"not parquet")
    with pytest.raises(DatasetError, match="file-000.parquet"):
        reader.episode(1)


def test_video_timestamps_and_sizes(tmp_path: Path) -> None:
    encoder = video_mod.choose_encoder()
    levels = np.arange(6, dtype=np.uint8)[:, None, None, None] * 40
    frames = np.zeros((6, 128, 128, 3), dtype=np.uint8) + levels
    video_mod.encode_video(tmp_path / "v.mp4", frames, 20, encoder)
    decoded, times = video_mod.decode_video(tmp_path / "v.mp4")
    assert decoded.shape == frames.shape
    np.testing.assert_allclose(times, np.arange(6) / 20, atol=1e-6)
    assert np.abs(decoded.astype(np.int16) - frames).mean() < 4.0
    with pytest.raises(DatasetError, match="even"):
        video_mod.encode_video(tmp_path / "odd.mp4", np.zeros((2, 15, 16, 3), np.uint8), 20, encoder)


@pytest.mark.parametrize("encoder", video_mod.available_encoders())
def test_every_available_encoder_round_trips(tmp_path: Path, encoder: str) -> None:
    _, videos = episode(8, seed=0)
    video_mod.encode_video(tmp_path / "v.mp4", videos[CAMS[0]], FPS, encoder)
    decoded, times = video_mod.decode_video(tmp_path / "v.mp4")
    assert decoded.shape == videos[CAMS[0]].shape and len(times) == 8
    assert np.abs(decoded.astype(np.int16) - videos[CAMS[0]]).mean() < 6.0


def test_chunks_without_cameras(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """chunks_size=2 and a file per episode: episode 2 opens chunk 1; a failure there leaves chunk 0
    alone; append works (and keeps the dataset's file size, not the writer's default)."""
    root = tmp_path / "ds"
    with writer(root, cameras={}, chunks_size=2, data_files_size_in_mb=1e-6) as w:
        for i in range(2):
            w.add_episode(episode(5 + i, seed=i)[0], task="t")
        before = listing(root)
        def broken_info(*args: int) -> None:
            raise OSError("disk full")

        monkeypatch.setattr(w, "_write_info", broken_info)
        with pytest.raises(OSError):
            w.add_episode(episode(4, seed=2)[0], task="new")
        assert listing(root) == before
        monkeypatch.undo()
        w.add_episode(episode(4, seed=2)[0], task="new")
    with writer(root, cameras={}, chunks_size=2) as w:
        assert w.add_episode(episode(3, seed=3)[0], task="t") == 3
    info = json.loads((root / "meta/info.json").read_text())
    assert info["video_path"] is None and info["total_frames"] == 18
    assert (root / "data/chunk-001/file-001.parquet").is_file()
    chunk1 = pq.read_table(root / "meta/episodes/chunk-001/file-000.parquet")
    assert chunk1.column("episode_index").to_pylist() == [2, 3]
    reader = DatasetReader(root)
    assert [reader.episode(i).length for i in range(4)] == [5, 6, 4, 3]
    assert reader.tasks == ["t", "new"] and reader.episode(3).frames["index"].tolist() == [15, 16, 17]
