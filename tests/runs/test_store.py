"""The SQLite store: what it writes survives a reopen, and a failed write leaves nothing behind."""

from __future__ import annotations

import sqlite3
from pathlib import Path

import pytest

from horde.runs.store import RunRecord, Store


def record(run_id: str = "r1", status: str = "paused", steps: int = 10) -> RunRecord:
    return RunRecord(run_id, "small", status, "", None, "{}", 1, steps, 1.0, 2.0)


def test_worlds_round_trip_across_a_reopen(tmp_path: Path) -> None:
    store = Store(tmp_path)
    assert store.put_world("room", '{"width": 5}') is True
    assert store.put_world("room", '{"width": 6}') is False
    store.close()
    store = Store(tmp_path)
    [world] = store.list_worlds()
    assert (world.name, world.spec) == ("room", '{"width": 6}') and store.count_worlds() == 1
    assert store.delete_world("room") and not store.delete_world("room")
    store.close()


def test_runs_snapshots_and_summaries(tmp_path: Path) -> None:
    store = Store(tmp_path)
    store.save_run(record(), snapshot=b"snap-1")
    store.save_run(record(status="finished", steps=20), snapshot=b"snap-2", summary='{"a": 1}')
    store.close()
    store = Store(tmp_path)
    [run] = store.list_runs()
    assert run.status == "finished" and run.steps == 20 and run.created_at == 1.0
    assert store.load_snapshot("r1") == b"snap-2" and store.load_summary("r1") == '{"a": 1}'
    store.save_run(record(status="created", steps=0))  # a reset: the summary goes, the snapshot stays
    assert store.load_summary("r1") is None and store.load_snapshot("r1") == b"snap-2"
    store.delete_run("r1")
    assert store.list_runs() == [] and store.load_snapshot("r1") is None
    assert store.integrity_check() == "ok"
    store.close()


def test_a_failed_write_is_rolled_back_whole(tmp_path: Path) -> None:
    store = Store(tmp_path)
    with pytest.raises(sqlite3.Error):
        store.save_run(record(), snapshot=object())  # type: ignore[arg-type]  # fails after the run's row
    assert store.list_runs() == []
    store.save_run(record(), snapshot=b"ok")  # the store is still usable
    assert store.load_snapshot("r1") == b"ok"
    store.close()


def test_write_ahead_log(tmp_path: Path) -> None:
    store = Store(tmp_path)
    store.close()
    with sqlite3.connect(tmp_path / "horde.db") as db:
        assert db.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
