"""A run's Monte-Carlo evaluations, kept with the run: the latest of each demon, in the store's database.

An evaluation (`POST /api/runs/{id}/evaluate`) is answered once; kept here, the dashboard shows it again
after a reload or from a shared link (`GET /api/runs/{id}/evaluations`). The rows go with their run
(deleted with it: a foreign key) and are dropped when the run is reset (its weights start again, so the
old truths no longer describe its predictions). The store holds JSON text; the server encodes and
decodes it.
"""

from __future__ import annotations

import sqlite3
import time

from horde.runs.errors import NotFoundError
from horde.runs.tables import Tables

EVALUATION_SCHEMA = """
CREATE TABLE IF NOT EXISTS evaluations (
    run_id TEXT NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
    demon TEXT NOT NULL,
    data TEXT NOT NULL,
    created_at REAL NOT NULL,
    PRIMARY KEY (run_id, demon)
);
"""


def keep_evaluation(store: Tables, run_id: str, demon: str, data: str) -> None:
    """Keep `data` (the evaluation's JSON) as the run's latest evaluation of `demon`.

    Raises:
        NotFoundError: the run is no longer stored (it was deleted meanwhile).
        StoreWriteError: the store refused the write.
    """
    try:
        store.write("INSERT OR REPLACE INTO evaluations VALUES (?, ?, ?, ?)", (run_id, demon, data, time.time()))
    except sqlite3.IntegrityError:
        raise NotFoundError(f"no run {run_id!r}") from None


def kept_evaluations(store: Tables, run_id: str) -> list[str]:
    """The run's kept evaluations (JSON), one per demon, oldest first."""
    rows = store.read("SELECT data FROM evaluations WHERE run_id = ? ORDER BY created_at", (run_id,))
    return [str(row[0]) for row in rows]


def forget_evaluations(store: Tables, run_id: str) -> None:
    """Drop the run's evaluations (it was reset)."""
    store.write("DELETE FROM evaluations WHERE run_id = ?", (run_id,))
