"""A full disk (issue 24, item 5): a JSON 503 that says so, runs saved or not made, and the message gone once
saving works again.

New rows meet a disk filled for real, portably and without root: SQLite's `PRAGMA max_page_count`, set to
the pages the file has, makes every write that needs one more page fail as a full disk does (SQLITE_FULL,
"database or disk is full", through SQLite's own failure and rollback); raising it again frees the space. A
rewrite of a row of the same size needs no new page, though on a full disk it fails all the same (the
write-ahead log must grow): for that case the store's connection is wrapped so that its writes raise
SQLite's error (`failing_writes`). Where the tests run as root, the last test does it all on a real 5 MB
tmpfs, filled by a file and freed by deleting it (the issue's reproducer).
"""

from __future__ import annotations

import contextlib
import os
import sqlite3
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

from horde.runs.store import Store
from horde.server import Settings, create_app
from polling import wait_until

from .helpers import WORLD, assert_healthy, make_spec

FULL = "database or disk is full"


@contextlib.contextmanager
def full_disk(store: Store) -> Iterator[None]:
    """No page beyond those the database has, until the block ends."""
    db = store._db  # the store's own connection: the limit is per connection
    with store._lock:
        pages = db.execute("PRAGMA page_count").fetchone()[0]
        allowed = db.execute("PRAGMA max_page_count").fetchone()[0]
        db.execute(f"PRAGMA max_page_count = {pages}")
    try:
        yield
    finally:
        with store._lock:
            db.execute(f"PRAGMA max_page_count = {allowed}")


class FailingWrites:
    """A connection whose INSERT, UPDATE and DELETE statements fail as on a full disk."""

    def __init__(self, db: sqlite3.Connection) -> None:
        self.db = db

    def execute(self, sql: str, *args: Any) -> sqlite3.Cursor:
        if sql.lstrip().split(" ", 1)[0].upper() in ("INSERT", "UPDATE", "DELETE"):
            raise sqlite3.OperationalError(FULL)
        return self.db.execute(sql, *args)

    @property
    def in_transaction(self) -> bool:
        return self.db.in_transaction


@contextlib.contextmanager
def failing_writes(store: Store) -> Iterator[None]:
    db = store._db
    with store._lock:
        store._db = FailingWrites(db)  # type: ignore[assignment]
    try:
        yield
    finally:
        with store._lock:
            store._db = db


def big_world(name: str) -> dict[str, Any]:
    """A world whose spec needs pages of its own: 60 zones, some 5 KB of JSON."""
    zones = [{"name": f"zone_number_{i}", "kind": "zone", "rect": [0, 0, 100 + i, 100]} for i in range(60)]
    return {**WORLD, "name": name, "regions": WORLD["regions"] + zones}


@pytest.fixture
def fast_saves(settings: Settings) -> Iterator[TestClient]:
    with TestClient(create_app(settings.model_copy(update={"snapshot_every": 0.2}))) as client:
        yield client


def test_put_world_on_a_full_disk_is_a_json_503_and_nothing_is_stored(client: TestClient) -> None:
    store = client.app.state.store  # type: ignore[attr-defined]
    with full_disk(store):
        response = client.put("/api/worlds/x", json=big_world("x"))
        assert response.status_code == 503, response.text
        assert response.headers["content-type"] == "application/json" and FULL in response.json()["detail"]
        assert client.post("/api/worlds", json=big_world("y")).status_code == 503
        assert_healthy(client)
    assert client.get("/api/worlds/x").status_code == 404
    assert client.put("/api/worlds/x", json=big_world("x")).status_code == 201  # space again: it is stored


def test_a_run_on_a_full_disk_is_not_created(client: TestClient) -> None:
    store = client.app.state.store  # type: ignore[attr-defined]
    with full_disk(store):
        response = client.post("/api/runs", json=make_spec(world=big_world("w")))
        assert response.status_code == 503, response.text
        assert "not created" in response.json()["detail"] and FULL in response.json()["detail"]
        assert client.get("/api/runs").json() == []
        assert store.list_runs() == []
        assert_healthy(client)
    assert client.post("/api/runs", json=make_spec()).status_code == 201


def test_not_saved_on_a_running_run_clears_once_a_save_works(fast_saves: TestClient) -> None:
    client = fast_saves
    store = client.app.state.store  # type: ignore[attr-defined]
    run_id = client.post("/api/runs", json=make_spec(), params={"hz": 200}).json()["id"]
    with failing_writes(store):
        started = client.post(f"/api/runs/{run_id}/start")
        assert started.status_code == 503 and FULL in started.json()["detail"], started.text
        run = client.get(f"/api/runs/{run_id}").json()
        assert run["status"] == "running" and "not saved" in run["message"], run
        assert_healthy(client)
    # Space again: the next periodic snapshot (every 0.2 s) is saved, and the message no longer says otherwise.
    cleared = wait_until(lambda: "not saved" not in (m := client.get(f"/api/runs/{run_id}").json())["message"] and m,
                         "the running run's message to drop 'not saved'")  # fmt: skip
    assert cleared["status"] == "running"
    assert next(r for r in store.list_runs() if r.id == run_id).message == cleared["message"]


@pytest.fixture
def tmpfs(tmp_path: Path) -> Iterator[Path]:
    """A 5 MB tmpfs, unmounted after the test (root only)."""
    mount = tmp_path / "tmpfs"
    mount.mkdir()
    if os.geteuid() != 0 or subprocess.run(["mount", "-t", "tmpfs", "-o", "size=5m", "tmpfs", str(mount)],
                                           capture_output=True).returncode != 0:  # fmt: skip
        pytest.skip("a tmpfs needs root and mount(8)")
    try:
        yield mount
    finally:
        subprocess.run(["umount", str(mount)], check=True)


def fill(directory: Path) -> Path:
    """A file that takes every free byte of the file system (ENOSPC ends it)."""
    filler = directory / "filler"
    with contextlib.suppress(OSError), filler.open("wb") as out:
        while True:
            out.write(b"\0" * 65536)
            out.flush()
    return filler


def test_a_real_full_tmpfs_answers_503s_and_recovers_once_space_is_freed(settings: Settings, tmpfs: Path) -> None:
    app = create_app(settings.model_copy(update={"data": tmpfs / "data", "snapshot_every": 0.2}))
    with TestClient(app) as client:
        run_id = client.post("/api/runs", json=make_spec(), params={"hz": 200}).json()["id"]
        filler = fill(tmpfs)
        world = client.put("/api/worlds/x", json=big_world("x"))
        assert world.status_code == 503 and FULL in world.json()["detail"], world.text
        created = client.post("/api/runs", json=make_spec(world=big_world("w")))
        assert created.status_code == 503 and "not created" in created.json()["detail"], created.text
        assert [r["id"] for r in client.get("/api/runs").json()] == [run_id]
        started = client.post(f"/api/runs/{run_id}/start")
        assert started.status_code == 503 and FULL in started.json()["detail"], started.text
        assert "not saved" in client.get(f"/api/runs/{run_id}").json()["message"]
        assert_healthy(client)
        filler.unlink()
        wait_until(lambda: "not saved" not in client.get(f"/api/runs/{run_id}").json()["message"],
                   "the running run's message to drop 'not saved' once space is freed")  # fmt: skip
        assert client.put("/api/worlds/x", json=big_world("x")).status_code == 201
        assert client.post("/api/runs", json=make_spec()).status_code == 201
        client.post(f"/api/runs/{run_id}/pause")
