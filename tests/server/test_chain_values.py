"""GET /api/runs/{id}/demons/{name}/values on a chain world: every state's value beside the truth (issue 25)."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient

from .helpers import locs


def test_a_chain_runs_values_are_every_states_prediction_beside_the_truth(client: TestClient) -> None:
    run = client.post("/api/runs", json={"scenario": "boyan-chain"}).json()["id"]
    before = client.get(f"/api/runs/{run}/demons/td/values")
    assert before.status_code == 200, before.text
    body = before.json()
    assert body["kind"] == "states" and body["x"] == list(range(12, 0, -1)) and body["y"] == []
    assert body["values"] == [[0.0] * 12]  # the weights start at 0
    assert body["exact"] == pytest.approx([-2.0 * s for s in range(12, 0, -1)])
    assert body["fixed_point"] == pytest.approx(body["exact"], abs=1e-9)  # Boyan's features represent -2 s
    assert body["rmsve"] > 5 and body["rms_error"] > 5 and body["rmspbe"] > 0.1 and "behaviour" in body["weighting"]
    client.post(f"/api/runs/{run}/step", json={"steps": 4000})
    after = client.get(f"/api/runs/{run}/demons/td/values").json()
    assert after["rmsve"] < 0.5 * body["rmsve"] and after["rmspbe"] < body["rmspbe"]
    assert after["values"][0][0] < -10  # state 12 on its way to -24
    grid = client.post("/api/runs", json={"scenario": "experiment1"}).json()["id"]
    demon = client.get(f"/api/runs/{grid}/demons").json()[0]["name"]
    assert client.get(f"/api/runs/{grid}/demons/{demon}/values?resolution=4").json()["kind"] == "grid"


def test_a_basis_order_or_a_state_count_past_its_bound_is_a_422_naming_the_field(client: TestClient) -> None:
    features = {"kind": "fourier", "order": 33, "sensors": [{"sensor": "state"}]}
    response = client.post("/api/runs", json={"scenario": "random-walk-19", "features": features})
    assert response.status_code == 422 and ["body", "features", "order"] in locs(response)
    world = {"kind": "gymnasium", "id": "horde/RandomWalk19-v0", "states": 4001}
    response = client.post("/api/runs", json={"scenario": "random-walk-19", "world": world})
    assert response.status_code == 422 and any(loc[-1] == "states" for loc in locs(response)), locs(response)
    world = {"kind": "gymnasium", "id": "horde/BoyanChain-v0", "states": 20}
    response = client.post("/api/runs", json={"scenario": "boyan-chain", "world": world})
    assert response.status_code == 422 and ["body", "world", "states"] in locs(response), response.text


def test_the_lab_lists_its_experiments_and_prepares_them_with_a_set_up(client: TestClient) -> None:
    lab = {e["id"]: e for e in client.get("/api/lab").json()}
    assert {"walk-19", "fig-12-3", "fig-11-5", "boyan-learners"} <= set(lab) and lab["walk-19"]["kind"] == "run"
    assert {s["name"] for s in lab["fig-12-3"]["setup"]} == {"alpha", "lambda", "runs"} and lab["fig-12-3"]["see"]
    prepared = client.post("/api/lab/walk-19/prepare", json={"setup": {"alpha": "0.05"}}).json()
    assert prepared["kind"] == "run" and prepared["spec"]["learning"]["alpha"] == 0.05
    created = client.post("/api/runs", json=prepared["spec"])
    assert created.status_code == 201, created.text
    study = client.post("/api/lab/boyan-learners/prepare", json={"setup": {"runs": "2"}}).json()
    assert study["kind"] == "study" and study["spec"]["runs"] == 2 and study["spec"]["caption"]
    bad = client.post("/api/lab/walk-1000/prepare", json={"setup": {"order": "40"}})
    assert bad.status_code == 422 and ["body", "setup", "order"] in locs(bad), bad.text
    assert client.post("/api/lab/nothing/prepare", json={}).status_code == 404


def test_a_chain_runs_history_records_rmsve_and_rmspbe_as_the_values_report_computes_them(client: TestClient) -> None:
    """Issue 25: RMSVE and RMSPBE are online measures, recorded in the run's history as RUPEE is. The recorded
    ones (`StateErrors`: projections computed once) equal GET .../values' (`DemonTruth`: the solve written
    out) at the same weights; a world without discrete states has none (null, not 0)."""
    run = client.post("/api/runs", json={"scenario": "random-walk-19"}).json()["id"]  # lambda 0.8: the trace
    for steps in (300, 700):
        assert client.post(f"/api/runs/{run}/step", json={"steps": steps}).status_code == 200
        for demon in ("td", "true_online_td"):
            history = client.get(f"/api/runs/{run}/demons/{demon}/history").json()
            values = client.get(f"/api/runs/{run}/demons/{demon}/values").json()
            assert history["step"][-1] == client.get(f"/api/runs/{run}").json()["step"]
            assert history["rmsve"][-1] == pytest.approx(values["rmsve"], rel=1e-9), demon
            assert history["rmspbe"][-1] == pytest.approx(values["rmspbe"], rel=1e-6, abs=1e-12), demon
            assert all(v is not None and v > 0 for v in history["rmsve"]), "every row carries a measurement"
    assert history["rmsve"][-1] < history["rmsve"][0], "the error falls as the demon learns"
    grid = client.post("/api/runs", json={"scenario": "experiment1"}).json()["id"]
    client.post(f"/api/runs/{grid}/step", json={"steps": 20})
    demon = client.get(f"/api/runs/{grid}/demons").json()[0]["name"]
    history = client.get(f"/api/runs/{grid}/demons/{demon}/history").json()
    assert history["prediction"] and history["rmsve"] is None and history["rmspbe"] is None
    export = client.get(f"/api/runs/{grid}/export/history?format=json").json()
    assert export and export[0]["rmsve"] is None and "rmspbe" in export[0]


def test_a_question_with_no_finite_answer_has_no_truth_and_its_run_learns_on(client: TestClient) -> None:
    """A discount of 1 on Baird's star (which never ends) asks for an infinite sum: I - M is singular. Its run
    still learns (its history carries no RMSVE for that demon, not a failed run), and its values have no truth,
    while a discounted demon beside it has one."""
    demons = [{"name": "forever", "learner": "td", "step_size": "autostep", "discount": 1.0},
              {"name": "discounted", "learner": "td", "discount": 0.9}]  # fmt: skip
    run = client.post("/api/runs", json={"scenario": "baird", "demons": demons}).json()["id"]
    state = client.post(f"/api/runs/{run}/step", json={"steps": 50})
    assert state.status_code == 200 and state.json()["step"] == 50, state.text
    assert client.get(f"/api/runs/{run}").json()["status"] != "failed"
    forever = client.get(f"/api/runs/{run}/demons/forever/values")
    assert forever.status_code == 200 and forever.json().get("exact") is None, forever.text
    assert client.get(f"/api/runs/{run}/demons/discounted/values").json()["exact"] is not None
    history = client.get(f"/api/runs/{run}/demons/forever/history").json()
    assert history["rmsve"] is not None and all(v is None for v in history["rmsve"]), history["rmsve"]
