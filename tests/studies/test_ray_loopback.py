"""The server's own Ray (a study with the default executor): every one of its processes listens on loopback
only, token authentication is on, and none is left dead or as a zombie, during the server's life or after."""

from __future__ import annotations

import os
from pathlib import Path
from unittest import mock

import pytest
from fastapi.testclient import TestClient

from horde.server import Settings, create_app
from polling import wait_until
from processes import descendants, is_loopback, listening

pytestmark = pytest.mark.slow
STUDY = {
    "scenario": "classroom-offpolicy",
    "runs": 1,
    "measure": {"episodes": 5, "checkpoints": 1},
    "axes": [{"path": "learning.alpha", "values": [0.03, 0.1]}],
}
RAY_NAMES = ("gcs_server", "raylet")


def wait_study(client: TestClient, study_id: str, timeout: float) -> None:
    def stopped() -> str:
        status: str = client.get(f"/api/studies/{study_id}").json()["status"]
        assert status not in ("created", "running"), status
        return status

    assert wait_until(stopped, f"study {study_id} to stop", timeout) == "finished"


@pytest.mark.timeout(280)
def test_the_servers_ray_listens_on_loopback_and_leaves_no_zombies(tmp_path: Path) -> None:
    me = os.getpid()
    with mock.patch.dict(os.environ):  # the local Ray's settings (RAY_*) go with it
        settings = Settings(data=tmp_path / "data", token=None, study_executor="ray", study_workers=1)
        with TestClient(create_app(settings)) as client:
            study = client.post("/api/studies", json=STUDY)
            assert study.status_code == 202, study.text
            wait_study(client, study.json()["id"], timeout=240)
            ray = descendants(me)
            assert {p.name for p in ray} >= set(RAY_NAMES), ray
            # The study's thread has ended; Ray's processes live on for the next study.
            assert not [p for p in ray if p.state == "Z"], ray
            sockets = listening([me, *(p.pid for p in ray)])
            assert {pid for pid, _, _ in sockets} > {me}, "the Ray processes listen"
            assert [s for s in sockets if not is_loopback(s[1])] == []
            assert os.environ["RAY_AUTH_MODE"] == "token" and len(os.environ["RAY_AUTH_TOKEN"]) == 64
            again = client.post("/api/studies", json=STUDY)  # on the same Ray
            wait_study(client, again.json()["id"], timeout=120)
        # The lifespan shut Ray down: its processes were stopped and waited for.
        wait_until(lambda: not descendants(me), "Ray's processes to be gone (no zombie left)", timeout=30)
