"""Baird's counterexample as a live run, as a class sees it: launched by name, TD marked diverged, the others not."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient

from .helpers import locs, messages


def test_the_baird_scenario_runs_live_and_the_table_marks_td_diverged(client: TestClient) -> None:
    created = client.post("/api/runs", json={"scenario": "baird"})
    assert created.status_code == 201, created.text
    run = created.json()["id"]
    start = client.get(f"/api/runs/{run}/state").json()
    state = int(start["sensors"]["state"])  # the star starts anywhere; the weights at (1, ..., 1, 10, 1)
    assert start["predictions"]["td"] == pytest.approx(3.0 if state < 6 else 12.0)
    client.post(f"/api/runs/{run}/step", json={"steps": 3000})
    middle = client.get(f"/api/runs/{run}/state").json()["predictions"]
    assert abs(middle["td"]) > 100, middle  # a hundred times its start within 3000 steps: TD is on its way out
    assert all(abs(middle[name]) < 100 for name in ("gtd", "gq", "etd")), middle
    for _ in range(3):  # near step 10,000 its prediction passes 1e12: the engine freezes it
        client.post(f"/api/runs/{run}/step", json={"steps": 5000})
    table = {d["name"]: d for d in client.get(f"/api/runs/{run}/demons").json()}
    assert table["td"]["metrics"]["diverged"] and table["td"]["prediction"] is None
    assert not any(table[name]["metrics"]["diverged"] for name in ("gtd", "gq", "etd")), table
    assert all(abs(table[name]["prediction"]) < 100 for name in ("gtd", "gq", "etd")), table
    events = client.get(f"/api/runs/{run}/state").json()["events"]
    assert any("'td' diverged" in event["message"] for event in events), events
    history = client.get(f"/api/runs/{run}/demons/td/history").json()
    assert max(abs(p) for p in history["prediction"] if p is not None) > 1e6  # the chart shows the blow-up
    assert history["prediction"][-1] is None  # and then stops: the frozen demon's zero weights answer nothing


def test_a_reset_starts_the_demons_from_their_initial_weights_again(client: TestClient) -> None:
    run = client.post("/api/runs", json={"scenario": "baird"}).json()["id"]
    client.post(f"/api/runs/{run}/step", json={"steps": 2000})
    assert client.post(f"/api/runs/{run}/reset").status_code == 200
    state = client.get(f"/api/runs/{run}/state").json()
    upper = int(state["sensors"]["state"]) < 6
    for name in ("td", "gtd", "gq", "etd"):  # v = 2 + 1 in an upper state, 10 + 2 in the lower one
        assert state["predictions"][name] == pytest.approx(3.0 if upper else 12.0), name


def test_bad_initial_weights_on_bairds_features_are_422s_and_autostep_learns_on_them(client: TestClient) -> None:
    demons = [{"name": "td", "learner": "td", "initial_weights": [1, 2, 3]}]
    response = client.post("/api/runs", json={"scenario": "baird", "demons": demons})
    assert ["body", "demons", 0, "initial_weights"] in locs(response) and "has 8 weights" in messages(response)
    # Baird's features have the value 2 (a table index listed twice): Autostep takes feature values into account
    # (issue 29), so it is no longer refused there
    demons = [{"name": "td", "learner": "td", "step_size": "autostep"}]
    response = client.post("/api/runs", json={"scenario": "baird", "demons": demons})
    assert response.status_code == 201, response.text
    state = client.post(f"/api/runs/{response.json()['id']}/step", json={"steps": 50}).json()
    assert state["step"] == 50 and state["predictions"]["td"] is not None


def test_a_baird_run_imported_from_its_snapshot_goes_on_bit_for_bit(client: TestClient) -> None:
    run = client.post("/api/runs", json={"scenario": "baird"}).json()["id"]
    client.post(f"/api/runs/{run}/step", json={"steps": 700})
    twin = client.post("/api/runs/import", json=client.get(f"/api/runs/{run}/snapshot").json()).json()["id"]
    first = client.post(f"/api/runs/{run}/step", json={"steps": 500}).json()
    second = client.post(f"/api/runs/{twin}/step", json={"steps": 500}).json()
    assert first["step"] == second["step"] == 1200 and first["predictions"] == second["predictions"]
    assert client.get(f"/api/runs/{run}/state").json()["sensors"] == client.get(f"/api/runs/{twin}/state").json()[
        "sensors"]  # fmt: skip
