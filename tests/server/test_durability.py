"""Durable work: protocol jobs in the store, periodic snapshots encoded off the worker's loop, written by the API.

(The hard kills themselves are in test_kill_loop.py and test_restart.py.)
"""

from __future__ import annotations

import threading
import time
from pathlib import Path
from typing import Any

from fastapi.testclient import TestClient

from horde.runs import recorder
from horde.runs.manager import RunManager
from horde.runs.recorder import Recorder
from horde.runs.run_setup import Limits, new_simulation
from horde.runs.session import RunSession
from horde.runs.snapshot import from_bytes
from horde.runs.store import Store
from horde.server import Settings, create_app
from horde.spec import RunSpec
from polling import wait_until
from workers import ThreadExecutor

from .helpers import make_spec, wait_protocol


def finished_job(client: TestClient, body: dict[str, Any]) -> dict[str, Any]:
    job = wait_protocol(client, client.post("/api/protocols", json=body).json()["id"])
    assert job["status"] == "finished", job
    return job


def test_protocol_jobs_outlive_the_server(tmp_path: Path) -> None:
    settings = Settings(data=tmp_path / "data", token=None, snapshot_every=3600.0)
    with TestClient(create_app(settings)) as client:
        short = {"scenario": "experiment1", "protocol": {"trials": 1, "episodes": 50}}
        done = finished_job(client, short)
        forgotten = finished_job(client, short)
        assert client.delete(f"/api/protocols/{forgotten['id']}").status_code == 200
        long = {"scenario": "experiment1", "protocol": {"episodes": 1_000_000}}
        running = client.post("/api/protocols", json=long).json()
        wait_until(
            lambda: client.get(f"/api/protocols/{running['id']}").json()["episodes_done"] > 0,
            "the long protocol to make progress",
        )

    with TestClient(create_app(settings)) as client:
        jobs = {j["id"]: j for j in client.get("/api/protocols").json()}
        assert set(jobs) == {done["id"], running["id"]}, "finished jobs come back, forgotten ones do not"
        assert jobs[done["id"]] == done
        interrupted = jobs[running["id"]]
        assert interrupted["status"] == "interrupted" and interrupted["episodes_done"] > 0, interrupted
        assert "stopped after" in interrupted["error"]
        # A new protocol may start: the interrupted one does not hold the slot.
        assert client.post("/api/protocols", json=short).status_code == 202


def test_periodic_snapshots_are_encoded_by_the_worker_and_written_by_the_saver_thread(tmp_path: Path) -> None:
    """The worker freezes the state in its loop and encodes it in its encoder thread; the API process writes it
    in its saver's thread (the worker never touches the store: a Ray actor on another node could not)."""
    store = Store(tmp_path)
    executor = ThreadExecutor()  # the worker in this process, to read its recorder
    manager = RunManager(store, Limits(snapshot_every=0.05), executor)
    writers: list[str] = []
    save_run = store.save_run

    def spy(*args: Any, **kwargs: Any) -> None:
        writers.append(threading.current_thread().name)
        save_run(*args, **kwargs)

    store.save_run = spy  # type: ignore[method-assign]
    try:
        run = manager.get(manager.create(RunSpec.model_validate(make_spec())).id)
        recorder = executor.workers[run.id].recorder
        run.start()
        wait_until(
            lambda: writers if recorder.snapshot_cost.write_seconds > 0 and writers.count("horde-saver") >= 4 else None,
            f"three periodic snapshots written by the saver (writers so far: {writers})",
        )
        data = store.load_snapshot(run.id)
        assert data is not None and from_bytes(data).status == "running"
        cost = recorder.snapshot_cost
        assert 0 < cost.freeze_seconds < cost.encode_seconds + cost.write_seconds, cost
    finally:
        manager.stop()
        store.close()
    assert set(writers) == {"horde-saver"}, writers


def test_a_slow_view_never_stretches_the_publish_interval_beyond_its_cap(monkeypatch: Any) -> None:
    """Issue 10, reproducer 6: one view that took long to make (the learner waited for the GIL) froze the
    published state for 80 s, as the interval was 20 times the wall time a view took. It is 20 times the
    learner thread's own CPU time now, and never more than MAX_PUBLISH_INTERVAL."""
    spec = RunSpec.model_validate(make_spec())
    sim = new_simulation(spec)
    session = RunSession(sim, Limits())
    sent: list[Any] = []
    rec = session.recorder = Recorder("r1", Limits(), sent.append, 0.0, sim.horde.names, persist=False)
    make_view = rec.make_view

    def waited() -> Any:  # wall time passes, this thread's CPU time does not
        time.sleep(0.3)
        return make_view(session)

    monkeypatch.setattr(rec, "make_view", lambda session: waited())
    began = time.monotonic()
    rec.publish(session, force=True)
    assert rec._next_publish - began <= 0.3 + 2 * recorder.PUBLISH_INTERVAL, "waiting is not the view's cost"

    def busy() -> Any:  # a view that really costs 0.2 s of CPU would ask for 4 s between publications
        end = time.thread_time() + 0.2
        while time.thread_time() < end:
            pass
        return make_view(session)

    monkeypatch.setattr(rec, "make_view", lambda session: busy())
    began = time.monotonic()
    rec.publish(session, force=True)
    assert rec._next_publish - began <= recorder.MAX_PUBLISH_INTERVAL + 0.01
    assert len(sent) == 2, "each forced publication sent an update"
