"""POST /api/runs/{id}/start | pause | reset | step and GET /api/runs/{id}/state: transitions and 409s."""

from __future__ import annotations

import sqlite3
import time
from collections.abc import Callable

import pytest
from fastapi.testclient import TestClient

from horde.runs.store import Store
from horde.runs.worker import MAX_LAG
from polling import wait_until

from .helpers import locs, make_spec, wait_for


def test_start_pause_resume(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run()
    assert client.post(f"/api/runs/{run_id}/start").json()["status"] == "running"
    assert client.post(f"/api/runs/{run_id}/start").status_code == 409
    assert client.post(f"/api/runs/{run_id}/step", json={"steps": 1}).status_code == 409
    wait_until(lambda: client.get(f"/api/runs/{run_id}").json()["step"] > 0, "the running run's first steps")
    paused = client.post(f"/api/runs/{run_id}/pause").json()
    assert paused["status"] == "paused" and paused["step"] > 0
    assert client.post(f"/api/runs/{run_id}/pause").status_code == 409
    time.sleep(0.1)
    assert client.get(f"/api/runs/{run_id}").json()["step"] == paused["step"]  # paused means still
    assert client.post(f"/api/runs/{run_id}/start").json()["status"] == "running"
    client.post(f"/api/runs/{run_id}/pause")


def test_pause_of_a_run_that_is_not_running_is_409(client: TestClient, create_run: Callable[..., str]) -> None:
    response = client.post(f"/api/runs/{create_run()}/pause")
    assert response.status_code == 409 and "created" in response.json()["detail"]


def test_step_takes_exactly_n_steps(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run()
    state = client.post(f"/api/runs/{run_id}/step", json={"steps": 25}).json()
    assert state["step"] == 25 and state["status"] == "paused"
    assert client.post(f"/api/runs/{run_id}/step").json()["step"] == 26  # default: one step
    assert ["body", "steps"] in locs(client.post(f"/api/runs/{run_id}/step", json={"steps": 0}))
    assert ["body", "steps"] in locs(client.post(f"/api/runs/{run_id}/step", json={"steps": 10**6}))


def test_reset_returns_to_the_first_step(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run()
    first = client.post(f"/api/runs/{run_id}/step", json={"steps": 40}).json()["predictions"]
    reset = client.post(f"/api/runs/{run_id}/reset").json()
    assert reset["status"] == "created" and reset["step"] == 0
    again = client.post(f"/api/runs/{run_id}/step", json={"steps": 40}).json()["predictions"]
    assert again == first  # same seed, same run


def test_a_finished_run_refuses_start_and_step_until_reset(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run(make_spec(episodes=2), start="true")
    finished = wait_for(client, run_id, "finished")
    assert finished["episode"] == 2 and finished["summary"]["episodes"] == 2
    assert set(finished["summary"]["predictions"]) == {"base", "steps"}
    assert client.post(f"/api/runs/{run_id}/start").status_code == 409
    assert client.post(f"/api/runs/{run_id}/step").status_code == 409
    assert client.post(f"/api/runs/{run_id}/reset").json()["status"] == "created"
    assert client.post(f"/api/runs/{run_id}/start").status_code == 200


def test_zero_episodes_runs_until_paused(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run(make_spec(episodes=0), start="true")
    body = wait_until(
        lambda: (b := client.get(f"/api/runs/{run_id}").json())["episode"] > 2 and b, "a third episode of the run"
    )
    assert body["status"] == "running"
    client.post(f"/api/runs/{run_id}/pause")


def test_hz_paces_the_run(client: TestClient, create_run: Callable[..., str]) -> None:
    began = time.monotonic()  # before the start: the time measured can only be longer than the run's
    run_id = create_run(make_spec(), start="true", hz=40)
    wait_until(lambda: client.get(f"/api/runs/{run_id}").json()["step"] >= 20, "20 paced steps")
    elapsed = time.monotonic() - began
    client.post(f"/api/runs/{run_id}/pause")
    # the first step comes at once and a lag of up to MAX_LAG is caught up: no faster than that
    assert elapsed >= 19 / 40 - MAX_LAG, f"20 steps in {elapsed:.3f} s: faster than 40 steps a second"


def test_state(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run()
    client.post(f"/api/runs/{run_id}/step", json={"steps": 300})
    state = client.get(f"/api/runs/{run_id}/state").json()
    assert state["run"] == run_id and state["step"] == 300 and state["status"] == "paused"
    assert 0 <= state["agent"]["x"] < 500 and 0 <= state["agent"]["y"] < 500
    assert set(state["predictions"]) == {"base", "steps"}
    assert set(state["metrics"]["steps"]) == {"rupee", "ude", "delta", "cumulant", "diverged", "step_size"}
    kinds = {e["kind"] for e in state["events"]}
    assert "episode" in kinds
    assert all(a["seq"] < b["seq"] for a, b in zip(state["events"], state["events"][1:], strict=False))


def test_unknown_run_is_404_everywhere(client: TestClient) -> None:
    for path in ("start", "pause", "reset", "step"):
        assert client.post(f"/api/runs/nope/{path}").status_code == 404
    assert client.get("/api/runs/nope/state").status_code == 404


def test_a_pause_that_cannot_be_saved_is_503_and_says_so(
    client: TestClient, create_run: Callable[..., str], monkeypatch: pytest.MonkeyPatch
) -> None:
    run_id = create_run()
    client.post(f"/api/runs/{run_id}/start")

    def disk_full(*args: object, **kwargs: object) -> None:
        raise sqlite3.OperationalError("database or disk is full")

    monkeypatch.setattr(Store, "save_run", disk_full)
    response = client.post(f"/api/runs/{run_id}/pause")
    assert response.status_code == 503, response.text
    assert "but it could not be saved: database or disk is full" in response.json()["detail"]
    run = client.get(f"/api/runs/{run_id}").json()
    assert run["status"] == "paused" and run["message"].endswith("; not saved: database or disk is full")
