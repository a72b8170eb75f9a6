"""The subtask database: one SQLite file (stdlib ``sqlite3``; the package's only importer of it).

Tables: ``scenes`` (id, source, spec), ``subtasks`` (skill, parameters, code and its hash, source
template or LLM with model and prompt hash, trials, successes, SR, Wilson interval, status, reason,
critic, versions) and ``trials`` (seed, outcome, failure class, duration) of each subtask.

The file is in WAL mode, so readers never block the one writer. Parallel workers each open their
own :class:`SubtaskStore`; a write waits up to ``busy_timeout`` seconds for the lock
(``BEGIN IMMEDIATE``) and a subtask is written with all its trials in one transaction, so the
database never holds a half-written row: a crash or an error rolls the whole subtask back. A file
that is locked for too long, read-only or not a database of this schema raises a typed
:class:`~vcage.errors.SubtaskStoreError` naming the file and what to change.
"""

from __future__ import annotations

import json
import sqlite3
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from vcage.errors import (
    CorruptSubtaskStoreError,
    SubtaskStoreError,
    SubtaskStoreLockedError,
    SubtaskStoreReadOnlyError,
)
from vcage.subtasks.records import SceneRecord, SubtaskRecord, TrialRecord

SCHEMA_VERSION = 1
SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS scenes (
  id TEXT PRIMARY KEY, source TEXT NOT NULL, spec TEXT NOT NULL, created TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS subtasks (
  id TEXT PRIMARY KEY, scene_id TEXT NOT NULL REFERENCES scenes(id),
  skill TEXT NOT NULL, parameters TEXT NOT NULL, description TEXT NOT NULL, predicates TEXT NOT NULL,
  code TEXT NOT NULL, code_hash TEXT NOT NULL,
  source TEXT NOT NULL CHECK (source IN ('template', 'llm')), model TEXT, prompt_hash TEXT,
  trials INTEGER NOT NULL CHECK (trials >= 0), successes INTEGER NOT NULL CHECK (successes >= 0),
  success_rate REAL NOT NULL, ci_low REAL NOT NULL, ci_high REAL NOT NULL,
  status TEXT NOT NULL CHECK (status IN ('accepted', 'rejected')), reason TEXT NOT NULL,
  critic TEXT, versions TEXT NOT NULL, created TEXT NOT NULL);
CREATE INDEX IF NOT EXISTS subtasks_scene ON subtasks(scene_id);
CREATE TABLE IF NOT EXISTS trials (
  subtask_id TEXT NOT NULL REFERENCES subtasks(id) ON DELETE CASCADE, trial INTEGER NOT NULL,
  seed INTEGER NOT NULL, outcome TEXT NOT NULL CHECK (outcome IN ('success', 'failure')),
  failure_class TEXT, detail TEXT NOT NULL, seconds REAL NOT NULL, PRIMARY KEY (subtask_id, trial));
"""
_SUBTASK_COLUMNS = ("id", "scene_id", "skill", "parameters", "description", "predicates", "code",
                    "code_hash", "source", "model", "prompt_hash", "trials", "successes", "success_rate",
                    "ci_low", "ci_high", "status", "reason", "critic", "versions", "created")


class SubtaskStore:
    """One connection to the subtask database at ``path`` (created if missing unless ``readonly``)."""

    def __init__(self, path: str | Path, busy_timeout: float = 30.0, readonly: bool = False) -> None:
        self.path = Path(path)
        self.busy_timeout = busy_timeout
        if readonly and not self.path.exists():
            raise SubtaskStoreError(f"no subtask database at {self.path}; run `vcage subtasks verify` "
                                    "to create one, or pass the right --db")
        with self._errors("open"):
            uri = f"file:{self.path.resolve()}?mode=ro" if readonly else str(self.path)
            self._conn = sqlite3.connect(uri, timeout=busy_timeout, isolation_level=None, uri=readonly)
        try:
            with self._errors("open"):
                self._conn.execute("PRAGMA foreign_keys = ON")
                if not readonly:
                    self._refuse_foreign_file()
                    self._conn.execute("PRAGMA journal_mode = WAL")
                    with self.transaction():
                        for statement in SCHEMA.split(";"):
                            if statement.strip():
                                self._conn.execute(statement)
                        self._conn.execute("INSERT OR IGNORE INTO meta VALUES ('schema_version', ?)",
                                           (str(SCHEMA_VERSION),))
                self._check_schema()
        except BaseException:
            self._conn.close()
            raise

    # -- lifetime -------------------------------------------------------------------------------
    def close(self) -> None:
        self._conn.close()

    def __enter__(self) -> SubtaskStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @contextmanager
    def transaction(self) -> Iterator[sqlite3.Connection]:
        """One write transaction: all of it is committed, or none of it (rolled back on any error)."""
        with self._errors("write"):
            self._conn.execute("BEGIN IMMEDIATE")
        try:
            yield self._conn
        except BaseException:
            self._conn.execute("ROLLBACK")
            raise
        with self._errors("write"):
            self._conn.execute("COMMIT")

    # -- writing --------------------------------------------------------------------------------
    def add_scene(self, scene: SceneRecord) -> None:
        with self.transaction() as conn, self._errors("write"):
            conn.execute("INSERT OR IGNORE INTO scenes VALUES (?, ?, ?, ?)",
                         (scene.id, scene.source, json.dumps(scene.spec, sort_keys=True), _now()))

    def put(self, record: SubtaskRecord, trials: Sequence[TrialRecord]) -> None:
        """Store ``record`` with its ``trials`` (replacing an earlier verification of the same id)."""
        row = _subtask_row(record)
        with self.transaction() as conn, self._errors("write"):
            conn.execute("DELETE FROM trials WHERE subtask_id = ?", (record.id,))
            conn.execute("DELETE FROM subtasks WHERE id = ?", (record.id,))
            conn.execute(f"INSERT INTO subtasks ({', '.join(_SUBTASK_COLUMNS)}) "
                         f"VALUES ({', '.join('?' * len(_SUBTASK_COLUMNS))})", row)
            conn.executemany("INSERT INTO trials VALUES (?, ?, ?, ?, ?, ?, ?)",
                             [(record.id, t.trial, t.seed, t.outcome, t.failure_class, t.detail, t.seconds)
                              for t in trials])

    # -- reading --------------------------------------------------------------------------------
    def subtasks(self, status: str | None = None, scene_id: str | None = None) -> list[SubtaskRecord]:
        """The stored subtasks (optionally of one status or scene), by scene then id."""
        where, args = [], []
        if status is not None:
            where.append("status = ?")
            args.append(status)
        if scene_id is not None:
            where.append("scene_id = ?")
            args.append(scene_id)
        sql = (f"SELECT {', '.join(_SUBTASK_COLUMNS)} FROM subtasks"
               + (f" WHERE {' AND '.join(where)}" if where else "") + " ORDER BY scene_id, id")
        with self._errors("read"):
            return [_subtask(r) for r in self._conn.execute(sql, args).fetchall()]

    def get(self, prefix: str) -> tuple[SubtaskRecord, list[TrialRecord]]:
        """The subtask whose id starts with ``prefix`` (unique), with its trials in order."""
        with self._errors("read"):
            rows = self._conn.execute(f"SELECT {', '.join(_SUBTASK_COLUMNS)} FROM subtasks WHERE id = ?",
                                      (prefix,)).fetchall() or self._conn.execute(
                f"SELECT {', '.join(_SUBTASK_COLUMNS)} FROM subtasks WHERE substr(id, 1, ?) = ? ORDER BY id "
                "LIMIT 3", (len(prefix), prefix)).fetchall()
            if len(rows) != 1 or not prefix:
                found = "no subtask" if not rows else f"{len(rows)}+ subtasks"
                raise SubtaskStoreError(f"{found} with an id starting {prefix!r} in {self.path}; "
                                        "`vcage subtasks list` shows the ids")
            record = _subtask(rows[0])
            trials = [TrialRecord(*r) for r in self._conn.execute(
                "SELECT trial, seed, outcome, failure_class, detail, seconds FROM trials "
                "WHERE subtask_id = ? ORDER BY trial", (record.id,)).fetchall()]
        return record, trials

    def scene(self, scene_id: str) -> SceneRecord:
        with self._errors("read"):
            row = self._conn.execute("SELECT id, source, spec FROM scenes WHERE id = ?",
                                     (scene_id,)).fetchone()
        if row is None:
            raise SubtaskStoreError(f"no scene {scene_id!r} in {self.path}")
        return SceneRecord(row[0], row[1], json.loads(row[2]))

    def counts(self) -> dict[str, int]:
        """Subtasks by status, and trials."""
        with self._errors("read"):
            by = dict(self._conn.execute("SELECT status, COUNT(*) FROM subtasks GROUP BY status").fetchall())
            trials = self._conn.execute("SELECT COUNT(*) FROM trials").fetchone()[0]
        return {"accepted": by.get("accepted", 0), "rejected": by.get("rejected", 0), "trials": trials}

    # -- errors ---------------------------------------------------------------------------------
    def _refuse_foreign_file(self) -> None:
        """An SQLite file with tables but no vcage schema is someone else's: never write into it."""
        tables = {r[0] for r in self._conn.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
        if tables and "meta" not in tables:
            raise CorruptSubtaskStoreError(
                f"{self.path} is an SQLite database but not a vcage subtask database (tables: "
                f"{', '.join(sorted(tables))}); pass another --db, or move the file aside")

    def _check_schema(self) -> None:
        try:
            row = self._conn.execute("SELECT value FROM meta WHERE key = 'schema_version'").fetchone()
        except sqlite3.OperationalError:  # no meta table: some other SQLite file
            row = None
        if row is None or row[0] != str(SCHEMA_VERSION):
            raise CorruptSubtaskStoreError(
                f"{self.path} is not a vcage subtask database of schema {SCHEMA_VERSION} "
                f"(found {row[0] if row else 'no schema version'}); pass another --db, or move the file "
                "aside")

    @contextmanager
    def _errors(self, doing: str) -> Iterator[None]:
        try:
            yield
        except sqlite3.Error as exc:
            raise translate(exc, self.path, doing, self.busy_timeout) from exc


def translate(exc: sqlite3.Error, path: Path, doing: str, busy_timeout: float) -> SubtaskStoreError:
    """The typed error for SQLite's ``exc`` on the database at ``path``, saying what to change."""
    text = str(exc)
    low = text.lower()
    if "locked" in low or "busy" in low:
        return SubtaskStoreLockedError(
            f"the subtask database {path} is locked by another process (waited {busy_timeout:g} s to "
            f"{doing}); let the other run finish, or raise the busy timeout")
    if "readonly" in low or "read-only" in low or "unable to open" in low or "permission" in low:
        return SubtaskStoreReadOnlyError(
            f"cannot {doing} the subtask database {path}: {text}; make the file and its directory "
            f"writable (WAL mode writes {path.name}-wal and {path.name}-shm beside it), or pass another --db")
    if isinstance(exc, sqlite3.DatabaseError) and ("not a database" in low or "malformed" in low
                                                   or "corrupt" in low):
        return CorruptSubtaskStoreError(
            f"{path} is not a readable SQLite database ({text}); move it aside to start a new one, or "
            "restore it from a backup")
    return SubtaskStoreError(f"cannot {doing} the subtask database {path}: {text}")


def _now() -> str:
    return datetime.now(UTC).isoformat(timespec="seconds")


def _subtask_row(r: SubtaskRecord) -> tuple[Any, ...]:
    return (r.id, r.scene_id, r.skill, json.dumps(r.parameters, sort_keys=True), r.description,
            json.dumps(list(r.predicates)), r.code, r.code_hash, r.source, r.model, r.prompt_hash, r.trials,
            r.successes, r.success_rate, r.ci_low, r.ci_high, r.status, r.reason, r.critic,
            json.dumps(r.versions, sort_keys=True), r.created or _now())


def _subtask(row: Sequence[Any]) -> SubtaskRecord:
    d = dict(zip(_SUBTASK_COLUMNS, row, strict=True))
    d["parameters"] = json.loads(d["parameters"])
    d["predicates"] = tuple(json.loads(d["predicates"]))
    d["versions"] = json.loads(d["versions"])
    return SubtaskRecord(**d)
