"""Content digests: every episode's row records what its files held when it committed, so a change of
content that leaves every file readable (a flipped byte inside a shared MP4, a value rewritten in a
parquet file, an extras file edited) and a deleted per-episode file are found by ``check`` and
``verify``, named on the episodes they touch, and refused by the writer before it appends. A fuzz
over random byte flips, truncations and deletions of every kind of file checks that no change of an
episode's content goes unfound, and that the repair keeps every episode whose content survived."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq
import pytest

from data.content import contents_by_episode
from vcage.data import DatasetWriter, Feature, digest
from vcage.data import video as video_mod
from vcage.data.columns import add_features
from vcage.data.repair import repair
from vcage.data.verify import check, verify
from vcage.errors import CorruptDatasetError

FPS = 10
CAMS = ("observation.images.front", "observation.images.wrist")
FEATURES = {"observation.state": Feature("float32", (4,)), "action": Feature("float32", (3,))}
LENGTHS = (9, 6, 11, 7)
DATA = "data/chunk-000/file-000.parquet"
EPISODES = "meta/episodes/chunk-000/file-000.parquet"


def video_path(key: str) -> str:
    return f"videos/{key}/chunk-000/file-000.mp4"


def open_writer(root: Path) -> DatasetWriter:
    """LeRobot's default file limits: all four episodes share one data file and one video per camera."""
    return DatasetWriter(root, fps=FPS, features=FEATURES, cameras=dict.fromkeys(CAMS, (32, 32)),
                         robot_type="panda", config={"digests": 1})


def add(w: DatasetWriter, seed: int) -> int:
    rng = np.random.default_rng(seed)
    length = LENGTHS[seed % len(LENGTHS)]
    frames = {"observation.state": rng.normal(size=(length, 4)).astype(np.float32),
              "action": rng.normal(size=(length, 3)).astype(np.float32)}
    yy, xx = np.mgrid[0:32, 0:32]
    videos = {key: np.asarray([np.stack([(xx * 4 + 9 * t + 40 * k) % 256, (yy * 4 + 17 * seed) % 256,
                                         np.full_like(xx, 50 + 9 * t)], -1) for t in range(length)],
                              dtype=np.uint8) for k, key in enumerate(CAMS)}
    return w.add_episode(frames, videos, task=f"task {seed % 2}", extras={"seed": seed},
                         arrays={"states": rng.normal(size=(length, 5))})


@pytest.fixture(scope="module")
def pristine(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("digests") / "ds"
    with open_writer(root) as w:
        for seed in range(len(LENGTHS)):
            add(w, seed)
    return root


@pytest.fixture()
def ds(pristine: Path, tmp_path: Path) -> Path:
    root = tmp_path / "ds"
    shutil.copytree(pristine, root)
    return root


def decoded(root: Path, key: str) -> dict[int, np.ndarray]:
    """Every episode's decoded frames of camera ``key``, each from its own time window."""
    rows = pq.read_table(root / EPISODES).to_pylist()
    return {i: video_mod.decode_window(root / video_path(key), row[f"videos/{key}/from_timestamp"],
                                       row[f"videos/{key}/to_timestamp"], FPS) for i, row in enumerate(rows)}


def test_every_row_records_the_digests_of_its_files(pristine: Path) -> None:
    rows = pq.read_table(pristine / EPISODES).to_pylist()
    columns = {digest.DATA, digest.EXTRAS, digest.STATES, *(digest.video_column(k) for k in CAMS)}
    assert all(isinstance(row[c], str) and len(row[c]) == 64 for row in rows for c in columns)
    assert len({row[digest.video_column(CAMS[0])] for row in rows}) == len(rows)  # one per episode
    assert check(pristine).ok and verify(pristine).ok
    for i, row in enumerate(rows):  # the extras and states digests are those of the files' bytes
        assert row[digest.EXTRAS] == digest.of_file(pristine / f"extras/episode_{i:06d}.json")
        assert row[digest.STATES] == digest.of_file(pristine / f"extras/episode_{i:06d}_states.npz")


def _silent_flip(path: Path, key: str, root: Path) -> set[int]:
    """Flip 64 bytes near the middle of the shared video ``path`` where the file still decodes but an
    episode's frames change (found by trying offsets); the episodes whose frames changed."""
    original = path.read_bytes()
    before = decoded(root, key)
    for fraction in np.linspace(0.3, 0.7, 41):
        data = bytearray(original)
        at = int(len(data) * fraction)
        data[at:at + 64] = bytes(b ^ 0xFF for b in data[at:at + 64])
        path.write_bytes(bytes(data))
        try:
            after = decoded(root, key)
        except CorruptDatasetError:
            continue  # this flip breaks decoding: any check finds that
        changed = {i for i in before if not np.array_equal(after[i], before[i])}
        if changed:
            return changed
    raise AssertionError("no flip near the middle decodes to other frames")


def test_bytes_flipped_inside_a_shared_video_are_found_and_an_append_is_refused(ds: Path) -> None:
    """The finding of 2026-12-05: 64 bytes flipped in the middle of a shared mp4 changed episode 1's
    decoded frames while every check passed and a later run appended to the dataset."""
    changed = _silent_flip(ds / video_path(CAMS[0]), CAMS[0], ds)
    for report in (check(ds), verify(ds)):
        assert changed <= set(report.damaged), report.summary()
        assert {p.path for p in report.problems} == {video_path(CAMS[0])}
    with pytest.raises(CorruptDatasetError, match="refusing to append"):
        open_writer(ds)


def test_a_deleted_states_file_is_found(ds: Path) -> None:
    (ds / "extras/episode_000001_states.npz").unlink()
    for report in (check(ds), verify(ds)):
        assert report.damaged == (1,) and "missing" in report.problems[0].what, report.summary()


def test_a_deleted_extras_file_is_found(ds: Path) -> None:
    (ds / "extras/episode_000002.json").unlink()
    report = check(ds)
    assert report.damaged == (2,) and report.problems[0].path == "extras/episode_000002.json"


def test_an_edited_extras_file_that_still_parses_is_found(ds: Path) -> None:
    path = ds / "extras/episode_000003.json"
    path.write_text(json.dumps({**json.loads(path.read_text()), "seed": 99}, indent=1))
    report = check(ds)
    assert report.damaged == (3,) and "content digest" in report.problems[0].what


def test_a_value_rewritten_in_a_shared_data_file_is_found_on_its_episode(ds: Path) -> None:
    table = pq.read_table(ds / DATA)
    mine = pc.equal(table.column("episode_index"), 2).to_numpy(zero_copy_only=False)
    action = table.column("action").to_pylist()
    row = int(np.flatnonzero(mine)[3])
    action[row] = [v + 1e-3 for v in action[row]]
    i = table.schema.get_field_index("action")
    field = table.schema.field("action")
    table = table.set_column(i, field, pa.array(action, field.type))
    pq.write_table(table, ds / DATA)
    for report in (check(ds), verify(ds)):
        assert report.damaged == (2,) and "rows' values differ" in report.problems[0].what, report.summary()


def test_a_backfilled_feature_keeps_the_digests_true(ds: Path) -> None:
    new = {"marker": Feature("float32", (1,))}
    assert add_features(ds, new, lambda i: {"marker": np.full((LENGTHS[i], 1), i, np.float32)}) == 1
    assert verify(ds).ok and check(ds).ok
    with open_writer_with(ds, new) as w:  # and an append after it
        add_with(w, new, 4)
    assert verify(ds).ok


def open_writer_with(root: Path, new: dict[str, Feature]) -> DatasetWriter:
    return DatasetWriter(root, fps=FPS, features={**FEATURES, **new}, cameras=dict.fromkeys(CAMS, (32, 32)),
                         robot_type="panda", config={"digests": 1})


def add_with(w: DatasetWriter, new: dict[str, Feature], seed: int) -> None:
    rng = np.random.default_rng(seed)
    length = 5
    frames = {"observation.state": rng.normal(size=(length, 4)).astype(np.float32),
              "action": rng.normal(size=(length, 3)).astype(np.float32),
              **{k: np.zeros((length, f.shape[0]), np.float32) for k, f in new.items()}}
    videos = {key: np.full((length, 32, 32, 3), 80, np.uint8) for key in CAMS}
    w.add_episode(frames, videos, task="task 0", extras={"seed": seed},
                  arrays={"states": np.zeros((length, 5))})


# ------------------------------------------------------------------------------------------ fuzz

KINDS = ("data", "video", "extras", "states", "episodes")


def _target(root: Path, kind: str, rng: np.random.Generator) -> Path:
    if kind == "data":
        return root / DATA
    if kind == "video":
        return root / video_path(CAMS[int(rng.integers(len(CAMS)))])
    if kind == "episodes":
        return root / EPISODES
    episode = int(rng.integers(len(LENGTHS)))
    return root / f"extras/episode_{episode:06d}{'.json' if kind == 'extras' else '_states.npz'}"


def _corrupt(path: Path, rng: np.random.Generator) -> str:
    data = bytearray(path.read_bytes())
    how = ("flip", "flip", "flip", "truncate", "delete")[int(rng.integers(5))]
    if how == "delete":
        path.unlink()
    elif how == "truncate":
        path.write_bytes(bytes(data[:int(rng.integers(len(data)))]))
    else:
        at = int(rng.integers(len(data)))
        width = int(rng.integers(1, 65))
        for k in range(at, min(at + width, len(data))):
            data[k] ^= int(rng.integers(1, 256))
        path.write_bytes(bytes(data))
    return how


def _content(root: Path) -> dict[str, object] | None:
    """What the episodes hold, read as a user's reader would (every table value, every decoded frame,
    every extras and states file); None where it cannot be read at all."""
    try:
        out: dict[str, object] = {}
        table = pq.read_table(root / DATA)
        for name in table.column_names:
            out[f"data/{name}"] = table.column(name).to_pylist()
        for key in CAMS:
            frames, _ = video_mod.decode_video(root / video_path(key))
            out[key] = frames.tobytes()
        for i in range(len(LENGTHS)):
            for suffix in (".json", "_states.npz"):
                out[f"{i}{suffix}"] = (root / f"extras/episode_{i:06d}{suffix}").read_bytes()
        out["rows"] = pq.read_table(root / EPISODES).to_pylist()
        return out
    except Exception:  # noqa: BLE001 - any failure to read is a damage the checks must find
        return None


def _intact(root: Path, pristine: Path) -> set[int]:
    """The episodes whose content survived a corruption, judged from the files, not from the rows:
    their own extras and states files byte-identical, their rows of the shared data file readable
    and equal, and each camera's packets in their window byte-identical and decoding to the same
    frames."""
    rows = pq.read_table(pristine / EPISODES).to_pylist()
    out = set(range(len(LENGTHS)))
    for i in range(len(LENGTHS)):
        for suffix in (".json", "_states.npz"):
            rel = f"extras/episode_{i:06d}{suffix}"
            if not (root / rel).is_file() or (root / rel).read_bytes() != (pristine / rel).read_bytes():
                out.discard(i)
    try:
        table, original = pq.read_table(root / DATA), pq.read_table(pristine / DATA)
        for i in range(len(LENGTHS)):
            mine = pc.equal(table.column("episode_index"), i)
            if table.filter(mine).to_pylist() != original.filter(pc.equal(original.column("episode_index"),
                                                                            i)).to_pylist():
                out.discard(i)
    except Exception:  # noqa: BLE001 - an unreadable data file: no episode's rows survived
        return set()
    for key in CAMS:
        for i, row in enumerate(rows):
            window = (row[f"videos/{key}/from_timestamp"], row[f"videos/{key}/to_timestamp"], FPS)
            try:  # the same encoded bytes (what the episode holds; a flip in the encoder's SEI
                # changes them without changing a decoded pixel) that decode to the same frames
                same = video_mod.packet_digests(root / video_path(key), [window[:2]], FPS) == \
                    video_mod.packet_digests(pristine / video_path(key), [window[:2]], FPS) and \
                    np.array_equal(video_mod.decode_window(root / video_path(key), *window),
                                   video_mod.decode_window(pristine / video_path(key), *window))
            except Exception:  # noqa: BLE001 - its frames cannot be read
                same = False
            if not same:
                out.discard(i)
    return out


@pytest.mark.slow
def test_no_random_corruption_of_an_episode_s_content_goes_unfound(pristine: Path, tmp_path: Path) -> None:
    """200 random corruptions (byte flips of 1-64 bytes, truncations, deletions) of the data file, each
    camera's shared video, the extras and states files and the episodes' metadata. Each one either
    is found by ``verify`` or leaves everything a reader sees byte-identical (a flip in a part of
    an MP4 no frame is decoded from). Each one found is repaired: the dataset verifies after it,
    every episode it keeps holds exactly its original content, and no episode whose content
    survived (:func:`_intact`) is dropped."""
    rng = np.random.default_rng(20261205)
    reference = _content(pristine)
    assert reference is not None
    by_episode = contents_by_episode(pristine)
    found = harmless = kept = survived = 0
    missed: list[str] = []
    for trial in range(200):
        root = tmp_path / f"t{trial}"
        shutil.copytree(pristine, root)
        kind = KINDS[trial % len(KINDS)]
        path = _target(root, kind, rng)
        how = _corrupt(path, rng)
        report = verify(root)
        if not report.ok:
            found += 1
            intact = _intact(root, pristine)
            result = repair(root)
            what = f"trial {trial}: {how} {path.relative_to(root)}"
            assert result.after.ok, (what, result.summary())
            held = [i for i in range(len(LENGTHS)) if i not in result.dropped]
            assert contents_by_episode(root) == [by_episode[i] for i in held], what
            assert intact <= set(held), (what, sorted(intact), held)
            kept, survived = kept + len(held), survived + len(intact)
        elif _content(root) == reference:
            harmless += 1
        else:
            missed.append(f"{how} {path.relative_to(root)}")
        shutil.rmtree(root)
    print(f"corruptions found by verify: {found}; harmless (nothing a reader sees changed): {harmless}; "
          f"episodes kept by the repairs: {kept} (of {found * len(LENGTHS)}; {survived} survived)")
    assert not missed, missed
    assert found >= 180, (found, harmless)  # most corruptions change something a reader sees


# ------------------------------------------------------------------------------------------ schema

def _marker(root: Path) -> dict:
    return json.loads((root / "meta/vcage.json").read_text())


def test_a_new_dataset_says_its_schema_and_a_row_that_lost_its_digests_is_found(ds: Path) -> None:
    """Stripping the digests must not switch their checks off: a schema-2 dataset expects them."""
    from vcage.data.schema import SCHEMA

    assert _marker(ds)["schema"] == SCHEMA == 2
    rows = pq.read_table(ds / EPISODES)
    stripped = rows.set_column(rows.schema.get_field_index(digest.DATA), digest.DATA,
                               pa.array([None, *rows.column(digest.DATA).to_pylist()[1:]], pa.string()))
    pq.write_table(stripped, ds / EPISODES)
    report = check(ds)
    assert report.damaged == (0,) and "records no content digest vcage/sha256/data" in report.problems[0].what


def test_a_dataset_of_the_schema_before_digests_is_read_verified_and_appended(ds: Path) -> None:
    rows = pq.read_table(ds / EPISODES)
    pq.write_table(rows.drop_columns([c for c in rows.column_names if c.startswith(digest.PREFIX)]),
                   ds / EPISODES)
    marker = {k: v for k, v in _marker(ds).items() if k != "schema"}
    (ds / "meta/vcage.json").write_text(json.dumps(marker))
    assert verify(ds).ok
    with open_writer(ds) as w:
        add(w, 9)
    assert verify(ds).ok and "schema" not in _marker(ds)  # it keeps the schema it was made with
    assert pq.read_table(ds / EPISODES).column(digest.DATA).to_pylist()[:4] == [None] * 4


def test_a_dataset_of_a_newer_vcage_is_refused_not_misread(ds: Path) -> None:
    from vcage.data import DatasetReader
    from vcage.errors import DatasetError

    (ds / "meta/vcage.json").write_text(json.dumps({**_marker(ds), "schema": 99}))
    for read in (DatasetReader, open_writer, verify):
        with pytest.raises(DatasetError, match="newer vcage .schema 99"):
            read(ds)
