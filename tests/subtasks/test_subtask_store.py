"""The subtask database: round trip, one transaction per subtask, parallel writers, typed errors."""

from __future__ import annotations

import multiprocessing
import os
import sqlite3
from dataclasses import replace
from pathlib import Path

import pytest

from vcage.errors import (
    CorruptSubtaskStoreError,
    SubtaskStoreError,
    SubtaskStoreLockedError,
    SubtaskStoreReadOnlyError,
)
from vcage.subtasks.records import SceneRecord, SubtaskRecord, TrialRecord
from vcage.subtasks.store import SubtaskStore

SCENE = SceneRecord("scene0000001", "task:press_stapler@0", {"objects": []})


def record(i: int, successes: int = 7) -> SubtaskRecord:
    return SubtaskRecord(id=f"{i:016x}", scene_id=SCENE.id, skill="press", parameters={"obj": "stapler"},
                         description="press the stapler", predicates=("pressed(stapler)",),
                         code='[{"args": {"obj": "stapler"}, "skill": "press"}]', code_hash="ab" * 32,
                         source="template", trials=10, successes=successes, success_rate=successes / 10,
                         ci_low=0.4, ci_high=0.9, status="accepted" if successes > 5 else "rejected",
                         reason="SR", critic="image", versions={"vcage": "0.1.0"})


def trials(n: int = 3) -> list[TrialRecord]:
    return [TrialRecord(k, 100 + k, "success" if k else "failure", None if k else "oracle", "d", 0.5)
            for k in range(n)]


def test_a_subtask_round_trips_with_its_trials(tmp_path: Path) -> None:
    db = tmp_path / "s.db"
    with SubtaskStore(db) as store:
        store.add_scene(SCENE)
        store.put(record(1), trials())
        store.put(record(2, successes=5), trials(2))
        store.put(record(1, successes=9), trials(4))  # a re-verification replaces the row and its trials
    with SubtaskStore(db, readonly=True) as store:
        got, got_trials = store.get(record(1).id)
        assert store.get(record(2).id)[0].successes == 5
        with pytest.raises(SubtaskStoreError, match="2\\+ subtasks with an id starting '0000'"):
            store.get("0000")
        assert got.successes == 9 and got.versions == {"vcage": "0.1.0"}
        assert got.predicates == ("pressed(stapler)",)
        assert got_trials == trials(4)
        assert [r.id for r in store.subtasks(status="accepted")] == [record(1).id]
        assert store.counts() == {"accepted": 1, "rejected": 1, "trials": 6}
        assert store.scene(SCENE.id) == SCENE
    assert sqlite3.connect(db).execute("PRAGMA journal_mode").fetchone()[0] == "wal"


def test_a_failed_write_leaves_no_half_written_row(tmp_path: Path) -> None:
    with SubtaskStore(tmp_path / "s.db") as store:
        store.add_scene(SCENE)
        bad = [*trials(2), TrialRecord(2, 7, "maybe")]  # violates the trials' CHECK constraint
        with pytest.raises(SubtaskStoreError):
            store.put(record(1), bad)
        assert store.subtasks() == [] and store.counts()["trials"] == 0
        store.put(record(1), trials())  # the store is still usable
        assert len(store.subtasks()) == 1


def _write_many(path: str, worker: int) -> None:
    with SubtaskStore(path, busy_timeout=30) as store:
        store.add_scene(SCENE)
        for i in range(10):
            store.put(record(worker * 100 + i), trials(5))


def test_parallel_workers_each_write_every_row(tmp_path: Path) -> None:
    db = str(tmp_path / "s.db")
    ctx = multiprocessing.get_context("fork")  # real processes, each with its own connection
    procs = [ctx.Process(target=_write_many, args=(db, w)) for w in range(3)]
    for p in procs:
        p.start()
    for p in procs:
        p.join(60)
        assert p.exitcode == 0
    with SubtaskStore(db, readonly=True) as store:
        assert len(store.subtasks()) == 30 and store.counts()["trials"] == 150


def test_a_locked_database_is_a_typed_error_naming_the_file(tmp_path: Path) -> None:
    db = tmp_path / "s.db"
    SubtaskStore(db).close()
    holder = sqlite3.connect(db, isolation_level=None)
    holder.execute("BEGIN EXCLUSIVE")
    try:
        with pytest.raises(SubtaskStoreLockedError) as err, SubtaskStore(db, busy_timeout=0.2) as store:
            store.put(record(1), trials())
        assert str(db) in str(err.value) and "busy timeout" in str(err.value)
    finally:
        holder.execute("ROLLBACK")
        holder.close()


def test_a_read_only_database_is_a_typed_error(tmp_path: Path) -> None:
    db = tmp_path / "s.db"
    with SubtaskStore(db) as store:
        store.add_scene(SCENE)
    with SubtaskStore(db, readonly=True) as store, pytest.raises(SubtaskStoreReadOnlyError, match="writable"):
        store.put(record(1), trials())
    if os.geteuid() != 0:  # root writes through file modes
        db.chmod(0o444)
        tmp_path.chmod(0o555)
        try:
            with pytest.raises(SubtaskStoreReadOnlyError):
                SubtaskStore(db).put(record(1), trials())
        finally:
            tmp_path.chmod(0o755)


@pytest.mark.parametrize("content", [b"this is not a database at all" * 100, b""])
def test_a_file_that_is_not_a_subtask_database_is_corrupt(tmp_path: Path, content: bytes) -> None:
    db = tmp_path / "s.db"
    if content:
        db.write_bytes(content)
    else:  # a real SQLite file of another schema
        sqlite3.connect(db).execute("CREATE TABLE other (x)").connection.commit()
    with pytest.raises(CorruptSubtaskStoreError, match="aside"):
        SubtaskStore(db)


def test_a_truncated_database_is_corrupt(tmp_path: Path) -> None:
    db = tmp_path / "s.db"
    with SubtaskStore(db) as store:
        store.add_scene(SCENE)
        for i in range(30):
            store.put(replace(record(i), reason="x" * 2000), trials(5))
    sqlite3.connect(db).execute("PRAGMA wal_checkpoint(TRUNCATE)").connection.close()
    data = db.read_bytes()
    db.write_bytes(data[: len(data) // 2])
    for suffix in ("-wal", "-shm"):
        Path(str(db) + suffix).unlink(missing_ok=True)
    with pytest.raises(CorruptSubtaskStoreError), SubtaskStore(db, readonly=True) as store:
        store.subtasks()


def test_a_missing_database_says_how_to_make_one(tmp_path: Path) -> None:
    with pytest.raises(SubtaskStoreError, match="vcage subtasks verify"):
        SubtaskStore(tmp_path / "none.db", readonly=True)
