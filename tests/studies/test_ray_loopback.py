"""The server's own Ray (a study with the default executor): every one of its processes listens on loopback
only, token authentication is on, and none is left dead or as a zombie, during the server's life or after.
The server itself never joins Ray: the study's driver is a worker process of the server's fork server."""

from __future__ import annotations

import os
import signal
import sys
from pathlib import Path
from typing import Any
from unittest import mock

import pytest
from fastapi.testclient import TestClient

from horde.runs import forkserver
from horde.server import Settings, create_app
from polling import wait_until
from processes import Proc, descendants, is_loopback, listening
from server.test_supervision import HealthWatch

pytestmark = pytest.mark.slow
STUDY = {
    "scenario": "classroom-offpolicy",
    "runs": 1,
    "measure": {"episodes": 5, "checkpoints": 1},
    "axes": [{"path": "learning.alpha", "values": [0.03, 0.1]}],
}
RAY_NAMES = ("gcs_server", "raylet")


def head_process(pid: int) -> Proc:
    return next(p for p in descendants(os.getpid()) if p.pid == pid)


def ray_processes(pid: int) -> list[Proc]:
    """The descendants of `pid` that are not the fork server or its workers (they serve the whole test run)."""
    server = forkserver.shared().pid
    workers = {p.pid for p in descendants(server)} if server is not None else set()
    return [p for p in descendants(pid) if p.pid != server and p.pid not in workers]


def wait_study(client: TestClient, study_id: str, timeout: float) -> None:
    def stopped() -> str:
        status: str = client.get(f"/api/studies/{study_id}").json()["status"]
        assert status not in ("created", "running"), status
        return status

    status = wait_until(stopped, f"study {study_id} to stop", timeout)
    assert status == "finished", client.get(f"/api/studies/{study_id}").json()["message"]


@pytest.mark.timeout(280)
def test_the_servers_ray_listens_on_loopback_and_leaves_no_zombies(tmp_path: Path) -> None:
    me = os.getpid()
    with mock.patch.dict(os.environ):  # nothing of Ray's settings may leak into the server's environment
        settings = Settings(data=tmp_path / "data", token=None, study_executor="ray", study_workers=1)
        with TestClient(create_app(settings)) as client:
            study = client.post("/api/studies", json=STUDY)
            assert study.status_code == 202, study.text
            wait_study(client, study.json()["id"], timeout=240)
            head = client.app.state.studies.local_ray  # type: ignore[attr-defined]

            def reaped() -> list[Proc]:
                """Ray's processes once none is a zombie. A worker that has just exited (`ray::IDLE`) is one
                until the raylet reaps it, a moment later: only one that stays is left behind."""
                ray = [head_process(head.pid), *descendants(head.pid)]
                assert not [p for p in ray if p.state == "Z"], ray
                return ray

            ray = wait_until(reaped, "Ray's exited workers to be reaped (no zombie left)", timeout=15)
            assert {p.name for p in ray} >= set(RAY_NAMES), ray
            # The study's driver has ended; Ray's processes live on for the next study.
            sockets = listening([p.pid for p in ray])
            servers = {p.pid for p in ray if p.name in RAY_NAMES}
            assert servers <= {pid for pid, _, _ in sockets}, "the GCS and the raylet listen"
            assert [s for s in sockets if not is_loopback(s[1])] == []
            assert head.env()["RAY_AUTH_MODE"] == "token" and len(head.env()["RAY_AUTH_TOKEN"]) == 64
            joined = "ray" in sys.modules and sys.modules["ray"].is_initialized()
            assert not joined, "the server never joins Ray itself"
            again = client.post("/api/studies", json=STUDY)  # on the same Ray
            wait_study(client, again.json()["id"], timeout=120)
        # The lifespan shut Ray down: its processes were stopped and waited for.
        wait_until(lambda: not ray_processes(me), "Ray's processes to be gone (no zombie left)", timeout=30)


@pytest.mark.timeout(280)
def test_a_study_whose_ray_dies_fails_and_resumes_once_ray_is_back(tmp_path: Path) -> None:
    """Issue 23, what must hold 2: Ray's GCS killed in the middle of a study. The server is not Ray's driver, so
    it stays up; the study's driver fails, the study is `failed` saying why, and resumed it runs on a new Ray."""
    # 16 tasks of about half a second each on a warm cache: seconds of work left after the first, while the
    # driver's Ray ends within about one of its GCS.
    long = {**STUDY, "runs": 8, "measure": {"episodes": 2000, "checkpoints": 1}}
    settings = Settings(data=tmp_path / "data", token=None, study_executor="ray", study_workers=1)
    with TestClient(create_app(settings)) as client:
        study_id = client.post("/api/studies", json=long).json()["id"]
        wait_until(lambda: client.get(f"/api/studies/{study_id}").json()["tasks_done"] > 0, "a first task", 180)
        head = client.app.state.studies.local_ray  # type: ignore[attr-defined]
        (gcs,) = [p for p in descendants(head.pid) if p.name == "gcs_server"]
        watch = HealthWatch(client)
        os.kill(gcs.pid, signal.SIGKILL)

        def ended() -> dict[str, Any] | None:
            body: dict[str, Any] = client.get(f"/api/studies/{study_id}").json()
            return body if body["status"] != "running" else None

        body = wait_until(ended, "the study to end with its Ray", timeout=90)
        assert watch.stop() < 1.0 and watch.checks >= 3, "the API answered all along"
        assert body["status"] == "failed" and body["message"], body
        # Said by the driver (Ray told it to exit) or, when its exit is seen first, by the server.
        assert 0 < body["tasks_done"] < 16 and "Ray" in body["message"] and "resume it" in body["message"], body
        wait_until(lambda: not head.alive(), "the dead Ray's head to have ended")
        assert not [p for p in ray_processes(os.getpid()) if p.state == "Z"], "no zombie of the dead Ray"
        resumed = client.post(f"/api/studies/{study_id}/resume")  # on a new Ray
        assert resumed.status_code == 202, resumed.text
        wait_study(client, study_id, timeout=200)
        assert client.get(f"/api/studies/{study_id}").json()["tasks_done"] == 16
