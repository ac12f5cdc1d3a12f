"""A run placed on the second node of a loopback two-node Ray cluster behaves as a local one (issue 23, what
must hold 4): start, pause, step, demons joining, the demon table, the WebSocket stream, the live view (its
snapshots and value maps), snapshot export, and a server restart, all through the API and the stream.

The head node has no CPUs, so the run's actor (one CPU) can only be placed on the worker node; the server
joins nothing itself: its Ray bridge (a worker process) is the cluster's driver.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

from horde.server import Settings, create_app
from horde.view.manager_source import ManagerSource
from polling import wait_until
from ray_cluster import Cluster, start_cluster
from sockets import receive_json

from .helpers import make_spec, wait_for

pytestmark = [pytest.mark.slow, pytest.mark.timeout(400)]
JOINING = {"name": "bump", "learner": "td", "policy": "uniform", "cumulant": {"sensor": "bump"}}


@pytest.fixture(scope="module")
def cluster(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Cluster]:
    running = start_cluster(tmp_path_factory.mktemp("ray"), head_cpus=0, worker_cpus=1)
    try:
        yield running
    finally:
        running.stop()


def test_a_run_on_the_second_node_works_as_a_local_one(
    cluster: Cluster, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    for name, value in cluster.env.items():  # the token the bridge joins with
        monkeypatch.setenv(name, value)
    settings = Settings(data=tmp_path / "data", token=None, ray_address=cluster.address, snapshot_every=0.5)
    assert settings.runs_on_ray()
    with TestClient(create_app(settings)) as client:
        created = client.post("/api/runs", json=make_spec(), params={"hz": 500})
        assert created.status_code == 201, created.text
        run: dict[str, Any] = created.json()
        run_id, worker = run["id"], run["worker"]
        assert worker["kind"] == "ray" and worker["node"] == cluster.worker_node and worker["alive"], worker
        assert client.post(f"/api/runs/{run_id}/start").json()["status"] == "running"
        wait_until(lambda: client.get(f"/api/runs/{run_id}").json()["step"] > 20, "the run to learn on the node")
        with client.websocket_connect(f"/api/runs/{run_id}/stream") as ws:  # the stream, fed by the node
            first = receive_json(ws, "the first state")
            later = receive_json(ws, "a later state")
            assert first["run"] == run_id and later["step"] > first["step"] and "base" in later["predictions"]
        paused = client.post(f"/api/runs/{run_id}/pause").json()
        assert paused["status"] == "paused"
        stepped = client.post(f"/api/runs/{run_id}/step", json={"steps": 7}).json()
        assert stepped["step"] == paused["step"] + 7
        joined = client.post(f"/api/runs/{run_id}/demons", json=JOINING)
        assert joined.status_code == 201, joined.text
        table = client.get(f"/api/runs/{run_id}/demons").json()  # the dashboard's table
        assert [d["name"] for d in table] == ["base", "steps", "bump"]
        client.post(f"/api/runs/{run_id}/step", json={"steps": 20})
        state = client.get(f"/api/runs/{run_id}/state").json()
        assert set(state["predictions"]) == {"base", "steps", "bump"} and state["metrics"]["bump"]["diverged"] is False
        values = client.get(f"/api/runs/{run_id}/demons/base/values", params={"resolution": 8}).json()
        assert np.isfinite(np.array(values["values"], dtype=float)).all()
        source = ManagerSource(client.app.state.manager)  # type: ignore[attr-defined]  # the live view's source
        view = source.snapshot(run_id)
        assert view.total_steps == state["step"] and set(view.predictions) == {"base", "steps", "bump"}
        assert source.value_map(run_id, "base", 8).tolist() == values["values"]
        snapshot = client.get(f"/api/runs/{run_id}/snapshot")
        assert snapshot.status_code == 200 and json.loads(snapshot.content)["total_steps"] == state["step"]
        history = client.get(f"/api/runs/{run_id}/demons/base/history").json()
        assert history["step"] and history["step"][-1] <= state["step"]
        steps = state["step"]

    with TestClient(create_app(settings)) as client:  # a restart: the run comes back on the cluster
        back = client.get(f"/api/runs/{run_id}").json()
        assert back["status"] == "paused" and back["step"] == steps, back
        assert back["worker"]["kind"] == "ray" and back["worker"]["node"] == cluster.worker_node
        assert client.post(f"/api/runs/{run_id}/step", json={"steps": 3}).json()["step"] == steps + 3
        assert client.post(f"/api/runs/{run_id}/start").json()["status"] == "running"
        wait_for(client, run_id, "running")
        assert client.delete(f"/api/runs/{run_id}").status_code == 204
