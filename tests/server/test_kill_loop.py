"""Hard kills (SIGKILL) at random moments, in a loop: nothing finished is lost, running work comes back.

`test_server_killed_at_random_moments`: the server runs a full-speed run, and in every other round a long
protocol job, and is killed at a random moment, KILLS times over, restarted on the same data each time.
After every restart the database passes `PRAGMA integrity_check`, every world, finished run and finished
protocol job is there unchanged, a protocol job that was running is back as `interrupted` with its
progress, and the running run is running again from a snapshot that cost it at most MAX_LOST_SECONDS of
learning (snapshots every 2 s, the default).

`test_store_killed_during_snapshot_writes`: a process that does nothing but write large snapshots is
killed at random moments (STORE_KILLS times), so most kills land during a write; the stored snapshot must
be whole every time, and no write that completed before a kill may be lost.
"""

from __future__ import annotations

import random
import signal
import sqlite3
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path
from typing import Any

import httpx
import pytest

from .helpers import WORLD, make_spec, wait_for, wait_protocol
from .test_restart import server

pytestmark = pytest.mark.serial  # kills at random moments of a server under a bound on what is lost: alone

KILLS = 10  # the figure (ten random kill -9s); each restart forks the workers anew
STORE_KILLS = 10
MAX_LOST_SECONDS = 5.0
SNAPSHOT_EVERY = 2.0  # the default, written out so that the test states what it measures


def integrity(data: Path) -> str:
    with sqlite3.connect(data / "horde.db") as db:
        return str(db.execute("PRAGMA integrity_check").fetchone()[0])


def restored_step(message: str) -> int:
    assert "from step " in message, message
    return int(message.split("from step ")[1].split(",")[0])


@pytest.mark.slow
def test_server_killed_at_random_moments(tmp_path: Path) -> None:
    """See the module. Why 70 lines: one loop of rounds whose state (the worlds, finished runs and jobs seen so
    far, the running run and job) carries from one kill to the next; each round's checks read all of it."""
    data, log = tmp_path / "data", tmp_path / "server.log"
    rng = random.Random(10)
    worlds: set[str] = set()
    finished_runs: dict[str, dict[str, Any]] = {}
    finished_jobs: dict[str, dict[str, Any]] = {}
    running_job: str | None = None
    run_id: str | None = None
    seen: list[tuple[float, int]] = []  # (time, step) of the running run, sampled during the round
    previous_start = killed_at = 0.0
    lost: list[float] = []
    startups: list[float] = []
    for round_ in range(KILLS):
        started = time.monotonic()
        with server(data, log, SNAPSHOT_EVERY) as (process, client):
            startups.append(time.monotonic() - started)
            healthy_at = time.monotonic()
            # Everything finished before is still there, unchanged.
            assert {w["name"] for w in client.get("/api/worlds").json()} >= worlds
            for rid, body in finished_runs.items():
                again = client.get(f"/api/runs/{rid}").json()
                assert again["status"] == "finished" and again["summary"] == body["summary"], again
            jobs = {j["id"]: j for j in client.get("/api/protocols").json()}
            for jid, body in finished_jobs.items():
                assert jobs[jid]["status"] == "finished" and jobs[jid]["results"] == body["results"]
            if running_job is not None:
                job = jobs[running_job]
                assert job["status"] in ("interrupted", "finished"), job
                if job["status"] == "interrupted":
                    assert "stopped after" in job["error"], job
                running_job = None
            # The running run is running again, from a recent snapshot.
            if run_id is None:
                run_id = client.post("/api/runs", json=make_spec(), params={"start": "true"}).json()["id"]
            else:
                body = client.get(f"/api/runs/{run_id}").json()
                assert body["status"] == "running", body
                # Learning lost: from the last moment of the previous round at which the run stood at its
                # restored step (or the previous round's start, if it was there all along) to the kill.
                restored = restored_step(body["message"])
                before = [t for t, step in seen if step <= restored]
                lost.append(killed_at - (max(before) if before else previous_start))
                assert lost[-1] <= MAX_LOST_SECONDS, (round_, restored, seen[-3:], lost)

            sampler = Sampler(str(client.base_url), run_id)

            # Work of this round: a world, a short finished run, and every other round a long protocol.
            name = f"w{round_}"
            assert client.put(f"/api/worlds/{name}", json={**WORLD, "name": name}).status_code in (200, 201)
            worlds.add(name)
            if round_ % 5 == 0:
                short = client.post("/api/runs", json=make_spec(episodes=2), params={"start": "true"}).json()
                finished_runs[short["id"]] = wait_for(client, short["id"], "finished", timeout=60.0)
            if round_ % 2 == 0:
                body = {"scenario": "experiment1", "seed": round_, "protocol": {"trials": 1, "episodes": 200}}
                job = client.post("/api/protocols", json=body).json()
                finished_jobs[job["id"]] = wait_protocol(client, job["id"], timeout=120.0)
                assert finished_jobs[job["id"]]["status"] == "finished", finished_jobs[job["id"]]
            else:
                body = {"scenario": "experiment1", "seed": round_, "protocol": {"episodes": 1_000_000}}
                running_job = client.post("/api/protocols", json=body).json()["id"]

            # Learn a while more, then kill at a random moment; meanwhile note how far the run got when.
            time.sleep(rng.uniform(0.2, 1.5))
            seen, previous_start = sampler.stop(), healthy_at
            killed_at = time.monotonic()
            process.send_signal(signal.SIGKILL)
            process.wait(timeout=30)
        assert integrity(data) == "ok"
    print(f"learning lost per kill (s): max {max(lost):.2f}, mean {sum(lost) / len(lost):.2f} over {len(lost)}")
    print(f"restart to healthy (s): max {max(startups):.2f}, mean {sum(startups) / len(startups):.2f}")


class Sampler:
    """Notes (time, step) of a run every 50 ms in a thread, until stopped."""

    def __init__(self, base_url: str, run_id: str) -> None:
        self.samples: list[tuple[float, int]] = []
        self._done = threading.Event()
        self._thread = threading.Thread(target=self._loop, args=(base_url, run_id), daemon=True)
        self._thread.start()

    def _loop(self, base_url: str, run_id: str) -> None:
        with httpx.Client(base_url=base_url, timeout=10.0) as client:
            while not self._done.is_set():
                self.samples.append((time.monotonic(), client.get(f"/api/runs/{run_id}").json()["step"]))
                time.sleep(0.05)

    def stop(self) -> list[tuple[float, int]]:
        self._done.set()
        self._thread.join(timeout=10)
        return self.samples


WRITER = textwrap.dedent(
    """
    import sys, time
    from pathlib import Path
    from horde.runs.store import RunRecord, Store

    store = Store(Path(sys.argv[1]))
    data = Path(sys.argv[2]).read_bytes()
    runs = store.list_runs()
    steps = runs[0].steps if runs else 0
    print("ready", flush=True)
    while True:
        steps += 1
        store.save_run(RunRecord("r", None, "running", "", None, "{}", 0, steps, 0.0, time.time()), data)
    """
)


@pytest.mark.slow
def test_store_killed_during_snapshot_writes(tmp_path: Path) -> None:
    """The writer does nothing but write a 100-demon snapshot, so a kill lands mid-write."""
    from horde.runs.run_setup import new_simulation
    from horde.runs.snapshot import capture, from_bytes, restore, to_bytes
    from horde.runs.store import Store
    from horde.spec import RunSpec

    demons = [{"name": f"d{i}", "cumulant": 1, "learner": "gtd"} for i in range(100)]
    spec = RunSpec.model_validate(
        make_spec(demons=demons, behaviour="uniform", features={"kind": "tiles", "tilings": 8, "tiles": 16})
    )
    sim = new_simulation(spec)
    sim.run(200)
    data = to_bytes(capture(sim, spec, "running", None, None))
    (tmp_path / "snapshot.bin").write_bytes(data)
    rng = random.Random(11)
    steps = 0
    for _ in range(STORE_KILLS):
        process = subprocess.Popen(
            [sys.executable, "-c", WRITER, str(tmp_path / "data"), str(tmp_path / "snapshot.bin")],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
        )
        assert process.stdout is not None
        assert process.stdout.readline().strip() == b"ready", process.stderr.read() if process.stderr else ""
        time.sleep(rng.uniform(0.1, 0.4))
        process.send_signal(signal.SIGKILL)
        process.wait(timeout=30)
        store = Store(tmp_path / "data")
        try:
            assert store.integrity_check() == "ok"
            assert store.load_snapshot("r") == data, "the snapshot is whole"
            record = store.list_runs()[0]
            assert record.steps > steps, "every round wrote, and nothing written before was lost"
            steps = record.steps
        finally:
            store.close()
    restore(from_bytes(data))
    print(f"{steps} snapshots of {len(data) / 1e6:.1f} MB written in {STORE_KILLS} killed processes")
