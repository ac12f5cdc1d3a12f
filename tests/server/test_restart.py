"""The server as a subprocess, killed hard (SIGKILL) mid-run and restarted on the same data directory.

Every world and finished run is still there, the database passes PRAGMA integrity_check, the paused
run resumes from its snapshot exactly, and the run that was running goes on running from its latest
periodic snapshot.
"""

from __future__ import annotations

import os
import signal
import sqlite3
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import httpx

from polling import wait_until
from serving import free_port

from .helpers import WORLD, make_spec, wait_for

STARTUP_TIMEOUT = 120.0  # the first start may compile the learning kernels


@contextmanager
def server(
    data: Path, log: Path, snapshot_every: float = 0.2, nice: int = 0
) -> Iterator[tuple[subprocess.Popen[bytes], httpx.Client]]:
    """`python -m horde.server` on a free loopback port (at niceness `nice`); killed on the way out."""
    port = free_port()
    env = {k: v for k, v in os.environ.items() if not k.startswith("HORDE_")}
    env["HORDE_SNAPSHOT_EVERY"] = str(snapshot_every)
    command = [sys.executable, "-m", "horde.server", "--host", "127.0.0.1", "--port", str(port), "--data", str(data)]
    with log.open("ab") as out:
        process = subprocess.Popen(
            [*command, "--log-level", "warning"],
            env=env,
            stdout=out,
            stderr=out,
            preexec_fn=(lambda: os.nice(nice)) if nice else None,
        )
    client = httpx.Client(base_url=f"http://127.0.0.1:{port}", timeout=30.0)
    try:

        def healthy() -> bool:
            assert process.poll() is None, log.read_text()  # a dead server fails at once
            try:
                return client.get("/api/health").status_code == 200
            except httpx.TransportError:
                return False

        wait_until(healthy, "the server to answer /api/health", STARTUP_TIMEOUT, interval=0.1)
        yield process, client
    finally:
        client.close()
        if process.poll() is None:
            process.kill()
        process.wait(timeout=30)


def snapshot_steps(data: Path, run_id: str) -> int:
    """The step count of the run's latest snapshot as committed to the database (0 before its first)."""
    with sqlite3.connect(data / "horde.db", timeout=10.0) as db:
        row = db.execute("SELECT steps FROM snapshots WHERE run_id = ?", (run_id,)).fetchone()
    return 0 if row is None else int(row[0])


def test_sigkill_mid_run_loses_nothing(tmp_path: Path) -> None:
    data, log = tmp_path / "data", tmp_path / "server.log"
    with server(data, log) as (process, client):
        for name in ("room", "hall"):
            assert client.post("/api/worlds", json={**WORLD, "name": name}).status_code == 201
        finished = client.post("/api/runs", json=make_spec(episodes=3), params={"start": "true"}).json()["id"]
        finished_body = wait_for(client, finished, "finished", timeout=60.0)

        paused = client.post("/api/runs", json=make_spec(), params={"start": "true"}).json()["id"]
        time.sleep(0.3)
        paused_body = client.post(f"/api/runs/{paused}/pause").json()
        paused_state = client.get(f"/api/runs/{paused}/state").json()
        twin = client.post("/api/runs/import", json=client.get(f"/api/runs/{paused}/snapshot").json()).json()["id"]

        running = client.post("/api/runs", json=make_spec(), params={"start": "true"}).json()["id"]
        wait_until(lambda: client.get(f"/api/runs/{running}").json()["step"] > 0, "the run to step", 30.0)
        running_steps = client.get(f"/api/runs/{running}").json()["step"]
        # A periodic snapshot taken after that step count was read: snapshots go on while the run runs.
        wait_until(lambda: snapshot_steps(data, running) > running_steps, "a periodic snapshot past it", 30.0)

        process.send_signal(signal.SIGKILL)
        process.wait(timeout=30)
    latest_snapshot = snapshot_steps(data, running)  # the run may have stepped and saved again before the kill

    with sqlite3.connect(data / "horde.db") as db:
        assert db.execute("PRAGMA integrity_check").fetchone()[0] == "ok"

    with server(data, log) as (_, client):
        assert {w["name"] for w in client.get("/api/worlds").json()} == {"room", "hall"}
        runs = {r["id"]: r for r in client.get("/api/runs").json()}
        assert set(runs) == {finished, paused, twin, running}

        again = client.get(f"/api/runs/{finished}").json()
        assert again["status"] == "finished" and again["summary"] == finished_body["summary"]

        assert runs[paused]["status"] == "paused" and runs[paused]["step"] == paused_body["step"]
        assert client.get(f"/api/runs/{paused}/state").json()["predictions"] == paused_state["predictions"]
        resumed = client.post(f"/api/runs/{paused}/step", json={"steps": 500}).json()
        reference = client.post(f"/api/runs/{twin}/step", json={"steps": 500}).json()
        assert resumed["predictions"] == reference["predictions"] and resumed["step"] == paused_body["step"] + 500

        # The running run goes on from its latest periodic snapshot, the last one written before the kill.
        assert runs[running]["status"] == "running", runs[running]
        restored = int(runs[running]["message"].split("from step ")[1].split(",")[0])
        assert restored == latest_snapshot > running_steps, (restored, latest_snapshot, running_steps)
        wait_until(lambda: client.get(f"/api/runs/{running}").json()["step"] > restored, "the run to go on", 30.0)
        assert client.post(f"/api/runs/{running}/pause").json()["step"] > restored

        with sqlite3.connect(data / "horde.db") as db:
            assert db.execute("PRAGMA integrity_check").fetchone()[0] == "ok"
