"""verify, check and repair on real files truncated for real: every damage is found and named, the
repair drops exactly the damaged episodes and keeps the others unchanged (renumbered), and the writer
and the export refuse a damaged dataset."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import h5py
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from data.content import contents_by_episode
from vcage.data import DatasetReader, DatasetWriter, Feature
from vcage.data.repair import repair
from vcage.data.robomimic import export_robomimic
from vcage.data.verify import check, verify
from vcage.errors import CorruptDatasetError, DatasetError

FPS = 10
CAM = "observation.images.front"
FEATURES = {"observation.state": Feature("float32", (4,), names=["a", "b", "c", "d"]),
            "action": Feature("float32", (3,))}
CONFIG = {"task": "integrity", "seed": 1}
LENGTHS = (8, 6, 7, 5)


def open_writer(root: Path) -> DatasetWriter:
    """Files of at most a byte: every episode gets files of its own, so each damage below costs one
    episode (tests/data/test_packing.py damages files that episodes share)."""
    return DatasetWriter(root, fps=FPS, features=FEATURES, cameras={CAM: (32, 32)}, robot_type="panda",
                         config=CONFIG, data_files_size_in_mb=1e-6, video_files_size_in_mb=1e-6)


def add(w: DatasetWriter, length: int, seed: int) -> int:
    rng = np.random.default_rng(seed)
    frames = {"observation.state": rng.normal(size=(length, 4)).astype(np.float32),
              "action": rng.uniform(-1, 1, size=(length, 3)).astype(np.float32)}
    yy, xx = np.mgrid[0:32, 0:32]
    video = np.asarray([np.stack([(xx * 4 + 9 * t) % 256, (yy * 4) % 256, np.full_like(xx, 50 + 9 * t)], -1)
                        for t in range(length)], dtype=np.uint8)
    extras = {"seed": 100 + seed, "attempt": seed % 2, "oracle_success": seed != 1, "plan": ["press"]}
    arrays = {"states": rng.normal(size=(length, 5)), "initial_state": np.zeros(5)}
    return w.add_episode(frames, {CAM: video}, task=f"task {seed % 2}", extras=extras, arrays=arrays)


def write_dataset(root: Path) -> Path:
    """The packed dataset of :data:`LENGTHS` these tests corrupt, written at ``root``."""
    with open_writer(root) as w:
        for seed, length in enumerate(LENGTHS):
            add(w, length, seed)
    return root


@pytest.fixture(scope="module")
def pristine(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_dataset(tmp_path_factory.mktemp("integrity") / "ds")


@pytest.fixture()
def ds(pristine: Path, tmp_path: Path) -> Path:
    root = tmp_path / "ds"
    shutil.copytree(pristine, root)
    return root


def truncate(path: Path, keep: float = 0.5) -> None:
    data = path.read_bytes()
    path.write_bytes(data[: int(len(data) * keep)])


def bad_crc(path: Path) -> None:
    """Give episode 2 real-sized states (longer than the header the cheap check reads), then change
    the CRC the zip directory records for them: their bytes no longer match."""
    states = np.random.default_rng(0).normal(size=(LENGTHS[2], 20000))
    np.savez_compressed(path, states=states, initial_state=np.zeros(5))
    data = bytearray(path.read_bytes())
    entry = data.index(b"PK\x01\x02")
    data[entry + 16] ^= 0xFF
    path.write_bytes(bytes(data))


def contents(root: Path) -> dict[str, bytes]:
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def episode_files(i: int) -> list[str]:
    return [f"data/chunk-000/file-{i:03d}.parquet", f"videos/{CAM}/chunk-000/file-{i:03d}.mp4",
            f"extras/episode_{i:06d}.json", f"extras/episode_{i:06d}_states.npz"]


DATA, VIDEO, EXTRAS, STATES = episode_files(2)
EPISODES, INFO = "meta/episodes/chunk-000/file-000.parquet", "meta/info.json"
# (file truncated, the episodes it costs)
CASES = [(DATA, (2,)), (VIDEO, (2,)), (STATES, (2,)), (EXTRAS, (2,)), (EPISODES, (0, 1, 2, 3)), (INFO, ())]
PER_EPISODE = [DATA, VIDEO, STATES, EXTRAS]


def test_a_copy_of_the_tables_alone_reads_its_frames_and_refuses_images(ds: Path) -> None:
    shutil.rmtree(ds / "videos")  # what a training machine is given: meta/ and data/
    with pytest.raises(CorruptDatasetError, match=r"file-000\.mp4 \(episode 0\) is missing"):
        DatasetReader(ds)
    tables = DatasetReader(ds, videos=False)
    assert [tables.episode(i).length for i in range(len(tables))] == list(LENGTHS)
    assert tables.episode(2).frames["action"].shape == (LENGTHS[2], 3)
    with pytest.raises(DatasetError, match="tables alone"):
        tables.video(0, CAM)
    (ds / tables.data_path(1).relative_to(ds)).unlink()  # the tables are still checked
    with pytest.raises(CorruptDatasetError, match=r"\(episode 1\) is missing"):
        DatasetReader(ds, videos=False)


def test_a_clean_dataset_verifies(ds: Path) -> None:
    full, cheap = verify(ds), check(ds)
    assert full.ok and cheap.ok, full.summary()
    assert (full.episodes, full.frames, full.decoded, cheap.decoded) == (4, sum(LENGTHS), True, False)
    assert "no problems" in full.summary()
    full.raise_if_damaged()  # nothing to raise


@pytest.mark.parametrize(("rel", "episodes"), CASES, ids=[c[0].split("/")[-1] for c in CASES])
def test_each_truncation_is_found_and_named(ds: Path, rel: str, episodes: tuple[int, ...]) -> None:
    truncate(ds / rel)
    for report in (verify(ds), check(ds)):
        assert not report.ok
        assert [p.path for p in report.problems] == [rel], report.summary()
        assert report.damaged == episodes
        if episodes:
            assert str(report.problems[0]).startswith(f"{rel} (episode")
        with pytest.raises(CorruptDatasetError, match=rel.replace(".", r"\.")):
            report.raise_if_damaged()


def test_a_few_bytes_cut_off_an_mp4_are_found_without_decoding(ds: Path) -> None:
    path = ds / VIDEO
    path.write_bytes(path.read_bytes()[:-10])  # still decodes to every frame; the last box is short
    report = check(ds)
    assert report.damaged == (2,) and "truncated" in report.problems[0].what


def test_damage_inside_an_npz_is_found_by_verify(ds: Path) -> None:
    bad_crc(ds / STATES)
    # the zip directory and the array headers are intact: the cheap checks find it by its digest
    cheap = check(ds)
    assert cheap.damaged == (2,) and "content digest" in cheap.problems[0].what
    report = verify(ds)
    assert report.damaged == (2,) and "CRC" in report.problems[0].what


def test_metadata_inconsistency_is_found(ds: Path) -> None:
    info = json.loads((ds / INFO).read_text())
    (ds / INFO).write_text(json.dumps(info | {"total_frames": info["total_frames"] + 1}))
    report = check(ds)
    assert [(p.path, p.episode) for p in report.problems] == [(INFO, None)]
    assert "frames" in report.problems[0].what


def test_a_time_window_that_disagrees_with_the_video_is_found_by_decoding(ds: Path) -> None:
    table = pq.read_table(ds / EPISODES)
    rows = table.to_pylist()
    rows[2][f"videos/{CAM}/to_timestamp"] = 3 / FPS  # the video holds 7 frames, the window 3
    pq.write_table(pa.Table.from_pylist(rows, schema=table.schema), ds / EPISODES)
    # the container holds the frames the episode needs; the packets in its window are not those written
    cheap = check(ds)
    assert cheap.damaged == (2,) and "content digest" in cheap.problems[0].what
    report = verify(ds)
    assert report.damaged == (2,) and {p.path for p in report.problems} == {VIDEO}
    assert any("decodes to 3 frames" in p.what for p in report.problems)


def test_repair_across_chunks_renumbers_the_episodes_after_the_damaged_one(tmp_path: Path) -> None:
    root = tmp_path / "ds"
    with DatasetWriter(root, fps=FPS, features=FEATURES, config=CONFIG, chunks_size=2,
                       data_files_size_in_mb=1e-6) as w:  # a data file per episode: 3 chunks
        for i in range(5):
            w.add_episode({"observation.state": np.full((3, 4), i, np.float32),
                           "action": np.zeros((3, 3), np.float32)}, task="t", extras={"seed": i})
    truncate(root / "extras/episode_000001.json")
    result = repair(root)
    assert (result.kept, result.dropped, result.renumbered) == (4, (1,), {2: 1, 3: 2, 4: 3})
    assert result.after.ok
    assert sorted(p.relative_to(root).as_posix() for p in (root / "meta/episodes").rglob("*.parquet")) == [
        "meta/episodes/chunk-000/file-000.parquet", "meta/episodes/chunk-001/file-000.parquet"]
    assert sorted(p.relative_to(root).as_posix() for p in (root / "data").rglob("*.parquet")) == [
        "data/chunk-000/file-000.parquet", "data/chunk-000/file-001.parquet",
        "data/chunk-001/file-000.parquet", "data/chunk-001/file-001.parquet"]
    reader = DatasetReader(root)
    assert [reader.extras(i)["seed"] for i in range(4)] == [0, 2, 3, 4]
    assert [reader.episode(i).frames["observation.state"][0, 0] for i in range(4)] == [0, 2, 3, 4]


def test_leftovers_beyond_the_commit_point_are_not_damage(ds: Path) -> None:
    shutil.copy(ds / DATA, ds / "data/chunk-000/file-004.parquet")
    (ds / "extras/episode_000004_states.npz").write_bytes(b"half a file")
    assert verify(ds).ok


@pytest.mark.parametrize("rel", PER_EPISODE, ids=[r.split("/")[-1] for r in PER_EPISODE])
def test_repair_drops_exactly_the_damaged_episode_keeps_the_rest_and_appends(ds: Path, rel: str) -> None:
    """Found on 2026-12-05: a damaged episode cost every healthy episode after it. Now only the
    damaged one goes; the one after it is renumbered with its content unchanged."""
    before, files_before = contents_by_episode(ds), contents(ds)
    truncate(ds / rel)
    result = repair(ds)
    assert (result.kept, result.dropped, result.renumbered, result.healthy_dropped) == (3, (2,), {3: 2}, ())
    assert list(result.reasons) == [2] and rel in result.reasons[2][0]
    assert result.after.ok and verify(ds).ok
    assert "dropped 1 damaged (2)" in result.summary() and rel in result.summary()
    assert "3 is now 2" in result.summary()
    assert contents_by_episode(ds) == [before[0], before[1], before[3]]
    after = contents(ds)
    for i in (0, 1):  # the episodes before the damaged one keep their files byte for byte
        assert all(after[f] == files_before[f] for f in episode_files(i))
    reader = DatasetReader(ds)
    assert (reader.num_episodes, reader.total_frames) == (3, sum(LENGTHS) - LENGTHS[2])
    with open_writer(ds) as w:
        assert add(w, 4, seed=7) == 3
    assert verify(ds).ok and DatasetReader(ds).episode(3).frames["index"][0] == sum(LENGTHS) - LENGTHS[2]


def test_verify_says_the_repair_keeps_the_healthy_episodes(ds: Path) -> None:
    truncate(ds / episode_files(1)[0])
    assert "drops the 1 damaged episode(s)" in verify(ds).summary()
    assert "keeps the 3 intact one(s), renumbered" in verify(ds).summary()
    result = repair(ds)
    assert (result.kept, result.dropped, result.renumbered) == (3, (1,), {2: 1, 3: 2})


def test_repair_rebuilds_lost_episode_rows_from_the_files(ds: Path) -> None:
    original = pq.read_table(ds / EPISODES).to_pylist()
    truncate(ds / EPISODES)
    result = repair(ds)
    assert (result.kept, result.dropped, result.rebuilt) == (4, (), (0, 1, 2, 3)) and result.after.ok
    rebuilt = pq.read_table(ds / EPISODES).to_pylist()
    for old, new in zip(original, rebuilt, strict=True):
        assert set(old) == set(new)
        exact = [k for k in old if not k.startswith(f"stats/{CAM}/")]  # image stats: from decoded frames
        assert {k: new[k] for k in exact} == {k: old[k] for k in exact}
        np.testing.assert_allclose(new[f"stats/{CAM}/mean"], old[f"stats/{CAM}/mean"], atol=0.02)
    with open_writer(ds) as w:
        assert add(w, 3, seed=9) == 4


def test_repair_rebuilds_a_lost_info_json_from_its_copy(ds: Path) -> None:
    original = json.loads((ds / INFO).read_text())
    truncate(ds / INFO)
    result = repair(ds)
    assert (result.kept, result.dropped) == (4, ()) and result.after.ok
    assert json.loads((ds / INFO).read_text()) == original


def test_repair_refuses_what_it_cannot_rebuild_and_changes_nothing(ds: Path) -> None:
    marker = ds / "meta/vcage.json"
    marker.write_text(json.dumps({k: v for k, v in json.loads(marker.read_text()).items() if k != "info"}))
    truncate(ds / INFO)
    before = contents(ds)
    with pytest.raises(CorruptDatasetError, match="restore it from a copy"):
        repair(ds)
    assert contents(ds) == before


def test_repair_of_a_clean_dataset_changes_nothing(ds: Path) -> None:
    before = contents(ds)
    result = repair(ds)
    assert not result.changed and result.kept == 4 and "nothing to repair" in result.summary()
    assert contents(ds) == before


def test_repair_waits_for_no_writer(ds: Path) -> None:
    with open_writer(ds), pytest.raises(DatasetError, match="another writer"):
        repair(ds)


@pytest.mark.parametrize("rel", PER_EPISODE + [EPISODES, INFO], ids=lambda r: r.split("/")[-1])
def test_the_writer_refuses_to_append_to_a_damaged_dataset(ds: Path, rel: str) -> None:
    truncate(ds / rel)
    before = contents(ds)
    with pytest.raises(CorruptDatasetError, match=rf"{rel.replace('.', '[.]')}.*vcage verify .* --repair"):
        open_writer(ds)
    assert contents(ds) == before
    open_writer(ds.parent / "elsewhere").close()  # the failed writer released nothing it should hold


@pytest.mark.parametrize("rel", [STATES, VIDEO, DATA], ids=lambda r: r.split("/")[-1])
def test_export_refuses_a_damaged_dataset(ds: Path, tmp_path: Path, rel: str) -> None:
    truncate(ds / rel)
    with pytest.raises(CorruptDatasetError, match=rel.replace(".", "[.]")):
        export_robomimic(ds, tmp_path / "demos.hdf5")
    assert not list(tmp_path.glob("*demos*"))


def test_export_turns_damage_the_cheap_checks_miss_into_an_error(ds: Path, tmp_path: Path) -> None:
    rows = pq.read_table(ds / EPISODES)  # a dataset written before content digests: the checks miss it
    pq.write_table(rows.drop_columns([c for c in rows.column_names if c.startswith("vcage/sha256/")]),
                   ds / EPISODES)
    marker = json.loads((ds / "meta/vcage.json").read_text())
    (ds / "meta/vcage.json").write_text(json.dumps({k: v for k, v in marker.items() if k != "schema"}))
    bad_crc(ds / STATES)  # zipfile raises BadZipFile when the array is read
    assert check(ds).ok
    with pytest.raises(CorruptDatasetError, match="episode 2.*npz"):
        export_robomimic(ds, tmp_path / "demos.hdf5")
    assert not list(tmp_path.glob("*demos*"))


def test_export_of_a_repaired_dataset_works(ds: Path, tmp_path: Path) -> None:
    truncate(ds / VIDEO)
    repair(ds)
    summary = export_robomimic(ds, tmp_path / "demos.hdf5")
    assert summary.demos == 3
    with h5py.File(summary.path, "r") as f:
        assert sorted(f["data"]) == ["demo_0", "demo_1", "demo_2"]


def test_reader_errors_on_damaged_files_are_corruption(ds: Path) -> None:
    truncate(ds / STATES)
    truncate(ds / EXTRAS)
    reader = DatasetReader(ds)
    with pytest.raises(CorruptDatasetError, match="npz"):
        reader.arrays(2)
    with pytest.raises(CorruptDatasetError, match="JSON"):
        reader.extras(2)


def test_a_lost_info_json_is_named_and_rebuilt(ds: Path) -> None:
    original = json.loads((ds / INFO).read_text())
    (ds / INFO).unlink()
    report = check(ds)
    assert [(p.path, p.episode, p.what) for p in report.problems] == [(INFO, None, "is missing")]
    with pytest.raises(CorruptDatasetError, match="verify .* --repair"):
        open_writer(ds)
    assert repair(ds).after.ok and json.loads((ds / INFO).read_text()) == original


def test_repair_of_a_damaged_first_episode_keeps_the_others(ds: Path) -> None:
    before = contents_by_episode(ds)
    truncate(ds / episode_files(0)[1])
    result = repair(ds)
    assert (result.kept, result.dropped, result.renumbered) == (3, (0,), {1: 0, 2: 1, 3: 2})
    assert contents_by_episode(ds) == before[1:] and result.after.ok
    with open_writer(ds) as w:
        assert add(w, 5, seed=4) == 3
    assert verify(ds).ok


def test_repair_of_every_episode_damaged_keeps_an_empty_dataset_that_appends(ds: Path) -> None:
    for i in range(len(LENGTHS)):
        truncate(ds / episode_files(i)[1])
    result = repair(ds)
    assert (result.kept, result.dropped) == (0, (0, 1, 2, 3))
    assert "kept no episode" in result.summary() and result.after.ok
    assert DatasetReader(ds).num_episodes == 0
    with open_writer(ds) as w:
        assert add(w, 5, seed=4) == 0
    assert verify(ds).ok and DatasetReader(ds).total_frames == 5


def test_a_report_says_when_repair_cannot_help(ds: Path) -> None:
    marker = ds / "meta/vcage.json"
    marker.write_text(json.dumps({k: v for k, v in json.loads(marker.read_text()).items() if k != "info"}))
    truncate(ds / INFO)
    report = verify(ds)
    assert not report.ok and not report.repairable and "cannot fix this" in report.summary()
    assert report.problems[0].path == INFO


def test_repair_sets_aside_what_it_drops_and_deletes_nothing(ds: Path) -> None:
    """Found on 2026-12-05: repair deleted the dropped episodes' files, intact ones included. They are
    moved, byte for byte, to quarantine/<time>/ with a note of why; the dataset reads, verifies and
    appends as before, and a later repair sets its own aside without touching the first."""
    before = contents(ds)
    truncate(ds / episode_files(2)[3])  # episode 2's states: episode 2 is dropped, 3 renumbered
    damaged = (ds / episode_files(2)[3]).read_bytes()
    result = repair(ds)
    assert result.kept == 3 and result.quarantine is not None and "nothing was deleted" in result.summary()
    aside = ds / result.quarantine
    for i in (2, 3):  # the files as they were, under their old names
        for rel in episode_files(i):
            kept_bytes = (aside / rel).read_bytes()
            assert kept_bytes == (damaged if rel == episode_files(2)[3] else before[rel]), rel
    note = (aside / "NOTE.md").read_text()
    assert episode_files(2)[3] in note and "dropped episode 2" in note
    assert verify(ds).ok and DatasetReader(ds).num_episodes == 3
    with open_writer(ds) as w:
        assert add(w, 4, seed=7) == 3
    truncate(ds / episode_files(3)[0])  # the appended episode's data
    again = repair(ds)
    assert again.quarantine not in (None, result.quarantine) and (aside / "NOTE.md").read_text() == note
    assert verify(ds).ok
