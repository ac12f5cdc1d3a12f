"""Protocol jobs: a scenario's whole protocol in the background, with progress and `horde run`'s results."""

from __future__ import annotations

import warnings

with warnings.catch_warnings():
    warnings.filterwarnings("ignore", message=".*install `httpx2`")
    from fastapi.testclient import TestClient

from horde.core.experiment import run_protocol
from horde.scenarios import find_scenario

from .helpers import wait_protocol


def test_a_control_protocol_reports_counts_beside_the_thesis(client: TestClient) -> None:
    body = {"scenario": "experiment3", "seed": 4, "protocol": {"trials": 2, "episodes": 300}}
    response = client.post("/api/protocols", json=body)
    assert response.status_code == 202, response.text
    started = response.json()
    assert started["status"] == "running" and started["episodes_total"] == 600
    job = wait_protocol(client, started["id"])
    assert job["status"] == "finished", job["error"]
    assert job["episodes_done"] == 600
    assert job["thesis_counts"] == {"positive": 100, "negative": 0, "none": 0}
    rows = {row["name"]: row for row in job["results"]}
    counts = rows["base"]["counts"]
    assert sum(counts.values()) == 2 * 10  # trials x test runs
    assert rows["colour"]["counts"] is None
    assert [j["id"] for j in client.get("/api/protocols").json()] == [started["id"]]


def test_results_equal_horde_run(client: TestClient) -> None:
    overrides = {"trials": 1, "episodes": 200, "evaluation": {"rollouts": 200, "cap": 10_000}}
    job = wait_protocol(
        client, client.post("/api/protocols", json={"scenario": "experiment1", "protocol": overrides}).json()["id"]
    )
    spec = find_scenario("experiment1")
    spec = spec.model_copy(update={"protocol": spec.protocol.model_validate(overrides)})
    expected = run_protocol(spec)
    rows = {row["name"]: row for row in job["results"]}
    for demon in expected.demons:
        assert rows[demon.name]["prediction"] == demon.prediction
        assert rows[demon.name]["truth"] == demon.truth
        assert rows[demon.name]["thesis"] == demon.thesis
    assert job["steps"] == expected.steps


def test_one_at_a_time_and_cancel(client: TestClient) -> None:
    long = client.post("/api/protocols", json={"scenario": "experiment1", "protocol": {"episodes": 100_000}}).json()
    busy = client.post("/api/protocols", json={"scenario": "experiment3"})
    assert busy.status_code == 429
    assert "one at a time" in busy.json()["detail"]
    assert client.delete(f"/api/protocols/{long['id']}").status_code == 200
    assert wait_protocol(client, long["id"])["status"] == "cancelled"
    assert client.delete(f"/api/protocols/{long['id']}").status_code == 200  # a finished job is forgotten
    assert client.get(f"/api/protocols/{long['id']}").status_code == 404


def test_bad_requests(client: TestClient) -> None:
    assert client.get("/api/protocols/nope").status_code == 404
    assert client.post("/api/protocols", json={"scenario": "no_such_scenario"}).status_code == 404
    response = client.post("/api/protocols", json={"scenario": "experiment1", "protocol": {"trials": 0}})
    assert response.status_code == 422
    assert "trials" in [str(part) for part in response.json()["detail"][0]["loc"]]
