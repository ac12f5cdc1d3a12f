"""Supervised workers (issue 23, what must hold 1): a worker that dies fails its run alone, the API answering
throughout; a worker that stops answering is reported and never waited on; after a restart a run that
crashed its worker is not resumed into the crash.

The crashes are real: SIGKILL from outside (as the OOM killer sends it), and a segmentation fault and an
abort inside the worker (a read of address 0, `os.abort()`), which a worker does on the test-only `Crash`
command when its server runs with HORDE_TEST_HOOKS (`test_hooks`).
"""

from __future__ import annotations

import os
import signal
import threading
import time
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest
from fastapi.testclient import TestClient

from horde.runs import link as link_module
from horde.runs import messages as m
from horde.runs import protocols
from horde.runs.link import WorkerLink
from horde.runs.store import Store
from horde.server import Settings, create_app
from horde.studies import jobs
from polling import wait_until

from .helpers import make_spec, wait_for

HEALTH_BOUND = 1.0  # seconds: /api/health never took longer, whatever the workers did


class HealthWatch:
    """GET /api/health every 20 ms in a thread, keeping the longest answer."""

    def __init__(self, client: TestClient) -> None:
        self.client = client
        self.longest = 0.0
        self.checks = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._watch, daemon=True)
        self._thread.start()

    def _watch(self) -> None:
        while not self._stop.wait(0.02):
            began = time.perf_counter()
            assert self.client.get("/api/health").status_code == 200
            self.longest = max(self.longest, time.perf_counter() - began)
            self.checks += 1

    def stop(self) -> float:
        self._stop.set()
        self._thread.join(10)
        return self.longest


def gone(pid: int) -> bool:
    """Whether the process is gone and reaped (no zombie left under its pid)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return True
    assert state != "Z", f"worker {pid} is a zombie"
    return False


@pytest.fixture
def hooked(tmp_path: Path) -> Settings:
    return Settings(data=tmp_path / "data", token=None, snapshot_every=0.2, test_hooks=True, worker_stall_seconds=2.0)


def start_run(client: TestClient) -> dict[str, Any]:
    response = client.post("/api/runs", json=make_spec(), params={"start": True})
    assert response.status_code == 201, response.text
    return dict(response.json())


def test_workers_that_die_fail_their_runs_alone_and_a_restart_does_not_resume_them(hooked: Settings) -> None:
    with TestClient(create_app(hooked)) as client:
        manager = client.app.state.manager  # type: ignore[attr-defined]
        killed, segv, aborted, survivor = (start_run(client) for _ in range(4))
        wait_until(lambda: all(client.get(f"/api/runs/{r['id']}").json()["step"] > 0
                               for r in (killed, segv, aborted)), "the runs to learn")  # fmt: skip
        # A snapshot of the run to kill, so that "its latest snapshot is kept" has one to keep.
        wait_until(lambda: Store(hooked.data).load_snapshot(killed["id"]), "a periodic snapshot of the run to kill")
        watch = HealthWatch(client)
        pids = {r["id"]: r["worker"]["pid"] for r in (killed, segv, aborted)}
        os.kill(pids[killed["id"]], signal.SIGKILL)
        manager.get(segv["id"]).crash("segv")
        manager.get(aborted["id"]).crash("abort")
        reasons = {killed["id"]: "signal 9 (SIGKILL)", segv["id"]: "signal 11 (SIGSEGV)",
                   aborted["id"]: "signal 6 (SIGABRT)"}  # fmt: skip
        for run_id, reason in reasons.items():
            body = wait_for(client, run_id, "failed")
            assert f"its worker died (killed by {reason})" in body["message"], body["message"]
            assert body["worker"]["alive"] is False
            events = client.get(f"/api/runs/{run_id}/state").json()["events"]
            assert any(e["kind"] == "error" and reason in e["message"] for e in events), events
            wait_until(lambda run_id=run_id: gone(pids[run_id]), f"worker {pids[run_id]} to be reaped")  # type: ignore[misc]
        assert "its latest snapshot (step " in client.get(f"/api/runs/{killed['id']}").json()["message"]
        # The survivor learns on; the API answered all along.
        before = client.get(f"/api/runs/{survivor['id']}").json()["step"]
        wait_until(lambda: client.get(f"/api/runs/{survivor['id']}").json()["step"] > before, "the survivor to learn")
        assert client.get(f"/api/runs/{survivor['id']}").json()["status"] == "running"
        # (the deaths can be handled faster than three checks: wait for them, so that the bound judges some)
        wait_until(lambda: watch.checks >= 3, "three health checks")
        longest = watch.stop()
        assert watch.checks >= 3 and longest < HEALTH_BOUND, (watch.checks, longest)
        # What needs a worker is a 409 naming the state; what the API process holds is still served.
        run = f"/api/runs/{killed['id']}"
        for method, path, body in [("POST", "/start", None), ("POST", "/step", {"steps": 1}),
                                   ("GET", "/snapshot", None), ("GET", "/demons/base/values", None),
                                   ("POST", "/demons", {"name": "x"}),
                                   ("POST", "/evaluate", {"demon": "steps", "episodes": 2})]:  # fmt: skip
            response = client.request(method, run + path, json=body)
            assert response.status_code == 409 and "it is failed" in response.json()["detail"], (path, response.text)
        assert client.get(f"{run}/state").status_code == 200 and client.get(f"{run}/demons").status_code == 200
        stored = Store(hooked.data)
        record = next(r for r in stored.list_runs() if r.id == killed["id"])
        assert record.status == "failed" and "SIGKILL" in record.message, "the store knows it failed, and why"
        assert stored.load_snapshot(killed["id"]) is not None, "its latest snapshot is kept"
        stored.close()

    with TestClient(create_app(hooked)) as client:  # a restart: the crashed runs are not resumed
        for run_id, reason in reasons.items():
            body = client.get(f"/api/runs/{run_id}").json()
            assert body["status"] == "failed" and reason in body["message"] and body["worker"]["kind"] == "none"
        assert client.get(f"/api/runs/{survivor['id']}").json()["status"] == "paused"
        assert client.post(f"/api/runs/{survivor['id']}/step", json={"steps": 5}).status_code == 200
        fresh = client.post(f"/api/runs/{killed['id']}/reset")  # a fresh worker, a fresh start
        assert fresh.status_code == 200 and fresh.json()["status"] == "created", fresh.text
        assert fresh.json()["worker"]["alive"] is True
        assert client.post(f"/api/runs/{killed['id']}/step", json={"steps": 5}).json()["step"] == 5


def test_a_worker_that_stops_answering_is_reported_and_never_waited_on(hooked: Settings) -> None:
    with TestClient(create_app(hooked)) as client:
        stuck = start_run(client)
        wait_until(lambda: client.get(f"/api/runs/{stuck['id']}").json()["step"] > 0, "the run to learn")
        client.app.state.manager.get(stuck["id"]).crash("hang")  # type: ignore[attr-defined]

        def reported() -> dict[str, Any] | None:
            body: dict[str, Any] = client.get(f"/api/runs/{stuck['id']}").json()
            return body if "its worker has not answered for" in body["message"] else None

        body = wait_until(reported, "the stall to be reported", timeout=hooked.worker_stall_seconds + 10)
        assert "busy with crash hang" in body["message"]
        began = time.monotonic()
        response = client.post(f"/api/runs/{stuck['id']}/pause")
        assert response.status_code == 409 and "has not answered" in response.json()["detail"], response.text
        assert time.monotonic() - began < 5.0, "a stalled worker is not waited on"
        assert client.get("/api/health").status_code == 200
        began = time.monotonic()
        assert client.delete(f"/api/runs/{stuck['id']}").status_code == 204
        assert time.monotonic() - began < 30.0, "deleting a stuck run ends its worker (terminated, then killed)"
        wait_until(lambda: gone(stuck["worker"]["pid"]), "the stuck worker to be gone")


class Stalls:
    """A listener that keeps what it hears of stalls."""

    def __init__(self) -> None:
        self.heard: list[tuple[float, str]] = []

    def on_stall(self, seconds: float, doing: str) -> None:
        self.heard.append((seconds, doing))


def test_a_stall_reported_before_the_beat_that_names_its_command_is_reported_again(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Under load the switchboard can report a stall before the worker's beat saying what holds it arrives (the
    test above once read "busy with" nothing): that beat updates the report; a beat that names nothing new adds
    nothing, and one whose loop moved again ends the stall."""
    now = [100.0]
    monkeypatch.setattr(link_module, "time", SimpleNamespace(monotonic=lambda: now[0]))
    stalls = Stalls()
    link = WorkerLink("process", lambda message: None, stalls)  # type: ignore[arg-type]
    link.deliver(m.Beat(progress=7))
    now[0] += 31.0
    link.check(30.0)
    assert stalls.heard == [(31.0, "")]
    now[0] += 0.5
    link.deliver(m.Beat(progress=7, doing="crash hang"))
    assert stalls.heard[-1] == (31.5, "crash hang")
    link.deliver(m.Beat(progress=7, doing="crash hang"))
    assert len(stalls.heard) == 2, "a beat that names the same command reports nothing more"
    link.deliver(m.Beat(progress=8))
    assert stalls.heard[-1] == (0.0, "") and not link.stalled


@pytest.mark.parametrize(
    ("listener", "logged"),
    [
        (lambda: protocols._JobWorker(None, SimpleNamespace(id="job-1")), "protocol job job-1: its worker"),  # type: ignore[arg-type]
        (lambda: jobs._StudyDriver(None, "study-1", None), "study study-1: its driver"),  # type: ignore[arg-type]
    ],
)
def test_a_protocol_job_or_study_logs_what_holds_its_stalled_worker(
    monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture, listener: Any, logged: str
) -> None:
    """The jobs without a page log their stalls: the report again once the beat names the command, so the log
    says what held the worker (the first report and the second read differently, not the same line twice)."""
    now = [100.0]
    monkeypatch.setattr(link_module, "time", SimpleNamespace(monotonic=lambda: now[0]))
    link = WorkerLink("process", lambda message: None, listener())
    link.deliver(m.Beat(progress=3))
    now[0] += 31.0
    with caplog.at_level("ERROR"):
        link.check(30.0)
        link.deliver(m.Beat(progress=3, doing="run"))
    assert [r.getMessage() for r in caplog.records] == [
        f"{logged} has not answered for 31 s",
        f"{logged} has not answered for 31 s (busy with run)",
    ]


def dead_stream_run(send: Any) -> Any:
    """A stream run whose link sends with `send` (no worker behind it)."""
    from horde.runs.stream_run import StreamRun
    from horde.spec import RunSpec
    from stream_specs import nexting, robot

    run = StreamRun("s1", RunSpec.model_validate(robot({"kind": "constant"}, nexting("light", 0.5))))
    run.link = WorkerLink("process", send, run)
    return run


def test_a_push_between_the_connections_close_and_the_exit_code_names_the_signal() -> None:
    """A worker's connection closes up to a second before its exit code is known (the executor waits for it): a
    call that fails in that window waits (in `WorkerLink.call`) for the end and names the signal (CI once read "it
    failed, ; delete it")."""
    from horde.runs.errors import ConflictError

    def closed(message: Any) -> None:
        raise OSError("connection closed")

    run = dead_stream_run(closed)
    reason = "killed by signal 11 (SIGSEGV)"
    later = threading.Timer(0.3, run.link.end, (reason,))
    later.start()
    try:
        with pytest.raises(ConflictError) as refused:
            run.push([{"observation": [0.0, 0.0], "action": 0}])
    finally:
        later.join(5.0)
    assert reason in str(refused.value)


def test_a_call_while_the_end_is_being_told_names_the_reason() -> None:
    """`WorkerLink.end` marks the link dead, then tells its listener: a call that finds it dead in between waits
    (`WorkerLink.gone`) and reads the state the end left, not the state before it."""
    from horde.runs.errors import ConflictError

    run = dead_stream_run(lambda message: None)
    told = run.on_exit

    def slowly(why: str) -> None:
        time.sleep(0.3)
        told(why)

    run.on_exit = slowly
    reason = "killed by signal 9 (SIGKILL)"
    ending = threading.Thread(target=run.link.end, args=(reason,))
    ending.start()
    try:
        wait_until(lambda: not run.link.alive, "the link marked dead", 5.0)
        with pytest.raises(ConflictError) as refused:
            run.push([{"observation": [0.0, 0.0], "action": 0}])
    finally:
        ending.join(5.0)
    assert reason in str(refused.value)


def test_a_stream_run_or_protocol_job_whose_worker_dies_says_so(hooked: Settings) -> None:
    from stream_specs import nexting, robot

    with TestClient(create_app(hooked)) as client:
        stream = client.post("/api/streams", json=robot({"kind": "constant"}, nexting("light", 0.5))).json()
        client.app.state.streams.get(stream["id"]).crash("segv")  # type: ignore[attr-defined]
        pushed = wait_until(lambda: (r := client.post(f"/api/streams/{stream['id']}/records", json={
            "records": [{"observation": [0.0, 0.0], "action": 0}]})).status_code == 409 and r,
            "a push to the dead stream run to be refused")  # fmt: skip
        assert "SIGSEGV" in pushed.json()["detail"]
        job = client.post("/api/protocols", json={"scenario": "experiment1", "protocol": {"episodes": 1_000_000}})
        wait_until(lambda: client.get(f"/api/protocols/{job.json()['id']}").json()["episodes_done"] > 0, "progress")
        os.kill(client.app.state.protocols.get(job.json()["id"]).link.pid, signal.SIGKILL)  # type: ignore[attr-defined]
        ended = wait_until(lambda: (j := client.get(f"/api/protocols/{job.json()['id']}").json())["status"] != "running"
                           and j, "the job to end")  # fmt: skip
        assert ended["status"] == "failed" and "killed by signal 9 (SIGKILL)" in ended["error"], ended
