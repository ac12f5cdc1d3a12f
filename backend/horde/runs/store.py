"""The SQLite store under the data directory: worlds, runs, run summaries, weight snapshots, protocol jobs
(and the tables of runs/evaluations.py, runs/owners.py and runs/tokens.py, through `read` and `write`).

One file, `horde.db`, in write-ahead-log mode. Every write is one transaction, so a crash (even
SIGKILL) leaves either the old or the new row, never half of one; a run's record, its latest
snapshot and its summary are written together. Only the latest snapshot of a run is kept.
The store knows JSON text and bytes, not the objects they encode (the run manager does that).
"""

from __future__ import annotations

import sqlite3
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from horde.runs.errors import StoreOpenError, StoreWriteError
from horde.runs.evaluations import EVALUATION_SCHEMA
from horde.runs.owners import OWNER_SCHEMA
from horde.runs.tokens import TOKEN_SCHEMA

DB_NAME = "horde.db"
SCHEMA_VERSION = 1
SCHEMA = """
CREATE TABLE IF NOT EXISTS worlds (
    name TEXT PRIMARY KEY,
    spec TEXT NOT NULL,
    created_at REAL NOT NULL,
    updated_at REAL NOT NULL
);
CREATE TABLE IF NOT EXISTS runs (
    id TEXT PRIMARY KEY,
    name TEXT,
    status TEXT NOT NULL,
    message TEXT NOT NULL,
    hz REAL,
    spec TEXT NOT NULL,
    episode INTEGER NOT NULL,
    steps INTEGER NOT NULL,
    created_at REAL NOT NULL,
    updated_at REAL NOT NULL
);
CREATE TABLE IF NOT EXISTS summaries (
    run_id TEXT PRIMARY KEY REFERENCES runs(id) ON DELETE CASCADE,
    data TEXT NOT NULL
);
CREATE TABLE IF NOT EXISTS snapshots (
    run_id TEXT PRIMARY KEY REFERENCES runs(id) ON DELETE CASCADE,
    steps INTEGER NOT NULL,
    created_at REAL NOT NULL,
    data BLOB NOT NULL
);
CREATE TABLE IF NOT EXISTS protocol_jobs (
    id TEXT PRIMARY KEY,
    spec TEXT NOT NULL,
    status TEXT NOT NULL,
    done INTEGER NOT NULL,
    total INTEGER NOT NULL,
    result TEXT,
    error TEXT NOT NULL,
    created_at REAL NOT NULL,
    updated_at REAL NOT NULL,
    finished_at REAL
);
"""
# Parameter studies (horde.studies): a study's spec and status, and one row per finished task, written
# as the task finishes, so that a study killed halfway resumes without redoing finished tasks.
STUDY_SCHEMA = """
CREATE TABLE IF NOT EXISTS studies (
    id TEXT PRIMARY KEY,
    name TEXT,
    spec TEXT NOT NULL,
    status TEXT NOT NULL,
    message TEXT NOT NULL,
    tasks INTEGER NOT NULL,
    created_at REAL NOT NULL,
    updated_at REAL NOT NULL
);
CREATE TABLE IF NOT EXISTS study_tasks (
    study_id TEXT NOT NULL REFERENCES studies(id) ON DELETE CASCADE,
    config INTEGER NOT NULL,
    run INTEGER NOT NULL,
    data TEXT NOT NULL,
    finished_at REAL NOT NULL,
    PRIMARY KEY (study_id, config, run)
);
"""


@dataclass(frozen=True)
class StudyRecord:
    id: str
    name: str | None
    spec: str  # StudySpec JSON, with the base run spec inlined
    status: str  # running, finished, failed, cancelled, interrupted
    message: str
    tasks: int  # configurations x runs
    created_at: float
    updated_at: float


@dataclass(frozen=True)
class StudyTaskRecord:
    config: int
    run: int
    data: str  # the task's measurements, JSON
    finished_at: float


@dataclass(frozen=True)
class WorldRecord:
    name: str
    spec: str  # WorldSpec JSON
    created_at: float
    updated_at: float


@dataclass(frozen=True)
class JobRecord:
    """A background job (a protocol) and how far it got; `result` is JSON once it finished."""

    id: str
    spec: str  # RunSpec JSON
    status: str
    done: int
    total: int
    result: str | None
    error: str
    created_at: float
    updated_at: float
    finished_at: float | None


@dataclass(frozen=True)
class RunRecord:
    id: str
    name: str | None
    status: str
    message: str
    hz: float | None
    spec: str  # RunSpec JSON
    episode: int
    steps: int
    created_at: float
    updated_at: float


class Store:
    """A thread-safe handle on the database (one connection, one lock).

    Args:
        directory: the data directory (created if missing).
    """

    def __init__(self, directory: Path) -> None:
        """Open (or create) the database and its tables.

        Raises:
            StoreOpenError: the directory cannot be made, or the database cannot be opened or written there.
        """
        self.path = directory / DB_NAME
        self._lock = threading.Lock()
        try:
            directory.mkdir(parents=True, exist_ok=True)
            self._db = sqlite3.connect(self.path, check_same_thread=False, isolation_level=None, timeout=30.0)
            self._db.execute("PRAGMA journal_mode=WAL")
            self._db.execute("PRAGMA synchronous=FULL")
            self._db.execute("PRAGMA foreign_keys=ON")
            with self._transaction() as db:
                for statement in (SCHEMA + STUDY_SCHEMA + EVALUATION_SCHEMA + OWNER_SCHEMA + TOKEN_SCHEMA).split(";"):
                    if statement.strip():
                        db.execute(statement)
                db.execute(f"PRAGMA user_version={SCHEMA_VERSION}")
        except (OSError, sqlite3.Error, StoreWriteError) as exc:
            reason = exc.__cause__ if isinstance(exc, StoreWriteError) else exc
            raise StoreOpenError(f"the data directory {directory} cannot hold the store: {reason}") from exc

    def close(self) -> None:
        with self._lock:
            self._db.close()

    @contextmanager
    def _transaction(self) -> Iterator[sqlite3.Connection]:
        """BEGIN IMMEDIATE ... COMMIT under the lock; ROLLBACK on any error.

        Raises:
            StoreWriteError: SQLite refused the write (a full disk, a read-only file, an I/O error); nothing of it
                was written.
        """
        with self._lock:
            try:
                self._db.execute("BEGIN IMMEDIATE")
                try:
                    yield self._db
                    self._db.execute("COMMIT")
                except BaseException:
                    if self._db.in_transaction:  # a failed COMMIT may have rolled back already
                        self._db.execute("ROLLBACK")
                    raise
            except sqlite3.OperationalError as exc:
                raise StoreWriteError(f"the store could not write: {exc}") from exc

    def _read(self, sql: str, args: tuple[object, ...] = ()) -> list[Any]:
        with self._lock:
            return list(self._db.execute(sql, args).fetchall())

    def read(self, sql: str, args: tuple[object, ...] = ()) -> list[Any]:
        """The rows of one query, for the modules that keep tables of their own here (evaluations, owners, tokens)."""
        return self._read(sql, args)

    def write(self, sql: str, args: tuple[object, ...] = ()) -> int:
        """One statement in a transaction of its own, for the modules that keep tables of their own here; the
        number of rows it changed.

        Raises:
            StoreWriteError: SQLite refused the write.
            sqlite3.IntegrityError: the statement breaks a constraint (say, a row of a run no longer stored).
        """
        with self._transaction() as db:
            return int(db.execute(sql, args).rowcount)

    def integrity_check(self) -> str:
        """SQLite's verdict on the file: "ok" when sound."""
        return str(self._read("PRAGMA integrity_check")[0][0])

    # ------------------------------------------------------------------------------------------
    # Worlds

    def list_worlds(self) -> list[WorldRecord]:
        rows = self._read("SELECT name, spec, created_at, updated_at FROM worlds ORDER BY name")
        return [WorldRecord(*row) for row in rows]

    def get_world(self, name: str) -> WorldRecord | None:
        rows = self._read("SELECT name, spec, created_at, updated_at FROM worlds WHERE name = ?", (name,))
        return WorldRecord(*rows[0]) if rows else None

    def count_worlds(self) -> int:
        return int(self._read("SELECT COUNT(*) FROM worlds")[0][0])

    def put_world(self, name: str, spec: str) -> bool:
        """Insert or replace a world; True when it is new."""
        now = time.time()
        with self._transaction() as db:
            exists = db.execute("SELECT 1 FROM worlds WHERE name = ?", (name,)).fetchone() is not None
            if exists:
                db.execute("UPDATE worlds SET spec = ?, updated_at = ? WHERE name = ?", (spec, now, name))
            else:
                db.execute("INSERT INTO worlds VALUES (?, ?, ?, ?)", (name, spec, now, now))
        return not exists

    def delete_world(self, name: str) -> bool:
        with self._transaction() as db:
            return db.execute("DELETE FROM worlds WHERE name = ?", (name,)).rowcount > 0

    # ------------------------------------------------------------------------------------------
    # Runs, summaries, snapshots

    def list_runs(self) -> list[RunRecord]:
        columns = "id, name, status, message, hz, spec, episode, steps, created_at, updated_at"
        rows = self._read(f"SELECT {columns} FROM runs ORDER BY created_at")
        return [RunRecord(*row) for row in rows]

    def save_run(self, record: RunRecord, snapshot: bytes | None = None, summary: str | None = None) -> None:
        """Write a run's record, and with it (in the same transaction) its snapshot and summary if given."""
        with self._transaction() as db:
            db.execute(
                "INSERT INTO runs VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?) ON CONFLICT(id) DO UPDATE SET "
                "name = excluded.name, status = excluded.status, message = excluded.message, hz = excluded.hz, "
                "spec = excluded.spec, episode = excluded.episode, steps = excluded.steps, "
                "updated_at = excluded.updated_at",
                (
                    record.id,
                    record.name,
                    record.status,
                    record.message,
                    record.hz,
                    record.spec,
                    record.episode,
                    record.steps,
                    record.created_at,
                    record.updated_at,
                ),
            )
            if snapshot is not None:
                db.execute(
                    "INSERT OR REPLACE INTO snapshots VALUES (?, ?, ?, ?)",
                    (record.id, record.steps, record.updated_at, snapshot),
                )
            if summary is not None:
                db.execute("INSERT OR REPLACE INTO summaries VALUES (?, ?)", (record.id, summary))
            elif record.status != "finished":
                db.execute("DELETE FROM summaries WHERE run_id = ?", (record.id,))

    def delete_run(self, run_id: str) -> None:
        with self._transaction() as db:
            db.execute("DELETE FROM runs WHERE id = ?", (run_id,))

    def load_snapshot(self, run_id: str) -> bytes | None:
        rows = self._read("SELECT data FROM snapshots WHERE run_id = ?", (run_id,))
        return bytes(rows[0][0]) if rows else None

    def load_summary(self, run_id: str) -> str | None:
        rows = self._read("SELECT data FROM summaries WHERE run_id = ?", (run_id,))
        return str(rows[0][0]) if rows else None

    # ------------------------------------------------------------------------------------------
    # Protocol jobs

    def save_protocol_job(self, job: JobRecord) -> None:
        """Insert or update a protocol job (its progress, status and result) in one transaction."""
        with self._transaction() as db:
            db.execute(
                "INSERT OR REPLACE INTO protocol_jobs VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                (
                    job.id,
                    job.spec,
                    job.status,
                    job.done,
                    job.total,
                    job.result,
                    job.error,
                    job.created_at,
                    job.updated_at,
                    job.finished_at,
                ),
            )

    def list_protocol_jobs(self) -> list[JobRecord]:
        columns = "id, spec, status, done, total, result, error, created_at, updated_at, finished_at"
        return [JobRecord(*row) for row in self._read(f"SELECT {columns} FROM protocol_jobs ORDER BY created_at")]

    def delete_protocol_job(self, job_id: str) -> None:
        with self._transaction() as db:
            db.execute("DELETE FROM protocol_jobs WHERE id = ?", (job_id,))

    # ------------------------------------------------------------------------------------------
    # Studies and their finished tasks

    def create_study(self, record: StudyRecord) -> None:
        with self._transaction() as db:
            db.execute(
                "INSERT INTO studies VALUES (?, ?, ?, ?, ?, ?, ?, ?)",
                (record.id, record.name, record.spec, record.status, record.message, record.tasks,
                 record.created_at, record.updated_at),
            )  # fmt: skip

    def set_study_status(self, study_id: str, status: str, message: str = "") -> None:
        with self._transaction() as db:
            db.execute(
                "UPDATE studies SET status = ?, message = ?, updated_at = ? WHERE id = ?",
                (status, message, time.time(), study_id),
            )

    def list_studies(self) -> list[StudyRecord]:
        rows = self._read("SELECT * FROM studies ORDER BY created_at")
        return [StudyRecord(*row) for row in rows]

    def get_study(self, study_id: str) -> StudyRecord | None:
        rows = self._read("SELECT * FROM studies WHERE id = ?", (study_id,))
        return StudyRecord(*rows[0]) if rows else None

    def delete_study(self, study_id: str) -> bool:
        with self._transaction() as db:
            return db.execute("DELETE FROM studies WHERE id = ?", (study_id,)).rowcount > 0

    def put_study_task(self, study_id: str, config: int, run: int, data: str) -> None:
        """Record one finished task (a repeat of a finished task keeps the first result)."""
        with self._transaction() as db:
            db.execute(
                "INSERT OR IGNORE INTO study_tasks VALUES (?, ?, ?, ?, ?)", (study_id, config, run, data, time.time())
            )

    def study_tasks(self, study_id: str) -> list[StudyTaskRecord]:
        rows = self._read(
            "SELECT config, run, data, finished_at FROM study_tasks WHERE study_id = ? ORDER BY config, run",
            (study_id,),
        )
        return [StudyTaskRecord(*row) for row in rows]

    def count_study_tasks(self, study_id: str) -> int:
        return int(self._read("SELECT COUNT(*) FROM study_tasks WHERE study_id = ?", (study_id,))[0][0])
