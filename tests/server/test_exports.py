"""Exports: a run's history as CSV and JSON, a run's spec as TOML, a protocol's results as CSV and JSON."""

from __future__ import annotations

import csv
import io
from collections.abc import Callable

from fastapi.testclient import TestClient

from horde.scenarios import parse_scenario
from horde.spec import RunSpec

from .helpers import wait_protocol


def test_a_runs_history_exports_as_csv_and_json_with_the_same_rows(
    client: TestClient, create_run: Callable[..., str]
) -> None:
    run_id = create_run()
    client.post(f"/api/runs/{run_id}/step", json={"steps": 30})
    response = client.get(f"/api/runs/{run_id}/export/history")
    assert response.status_code == 200 and response.headers["content-type"].startswith("text/csv")
    assert f'filename="run-{run_id}-history.csv"' in response.headers["content-disposition"]
    rows = list(csv.DictReader(io.StringIO(response.text)))
    assert list(rows[0]) == ["step", "demon", "prediction", "cumulant", "delta", "rupee", "ude", "rmsve", "rmspbe"]
    assert all(r["rmsve"] == r["rmspbe"] == "" for r in rows), "the grid has no discrete states: empty, not 0"
    as_json = client.get(f"/api/runs/{run_id}/export/history", params={"format": "json"}).json()
    assert len(rows) == len(as_json) > 0
    for row, record in zip(rows, as_json, strict=True):
        assert int(row["step"]) == record["step"] and row["demon"] == record["demon"]
        for quantity in ("prediction", "cumulant", "delta", "rupee", "ude"):
            assert (float(row[quantity]) if row[quantity] else None) == record[quantity]  # repr: exact
    # the export holds the same numbers as the demon's own history
    steps = client.get(f"/api/runs/{run_id}/demons/steps/history").json()
    mine = [r for r in as_json if r["demon"] == "steps"]
    assert [r["prediction"] for r in mine] == steps["prediction"]


def test_a_runs_spec_exports_as_toml_that_reads_back_as_the_same_spec(
    client: TestClient, create_run: Callable[..., str]
) -> None:
    run_id = create_run()
    response = client.get(f"/api/runs/{run_id}/export/spec")
    assert response.status_code == 200 and response.headers["content-type"].startswith("application/toml")
    spec = RunSpec.model_validate(client.get(f"/api/runs/{run_id}").json()["spec"])
    assert parse_scenario(response.text) == spec


def test_a_protocols_results_export_as_csv_and_json(client: TestClient) -> None:
    body = {"scenario": "experiment1", "protocol": {"trials": 1, "episodes": 50, "evaluation": {"rollouts": 50}}}
    job_id = client.post("/api/protocols", json=body).json()["id"]
    job = wait_protocol(client, job_id)
    assert job["status"] == "finished", job
    rows = list(csv.DictReader(io.StringIO(client.get(f"/api/protocols/{job_id}/export").text)))
    as_json = client.get(f"/api/protocols/{job_id}/export", params={"format": "json"}).json()
    results = {r["name"]: r for r in job["results"]}
    assert [r["demon"] for r in rows] == [r["demon"] for r in as_json] == list(results)
    for row, record in zip(rows, as_json, strict=True):
        assert float(row["prediction"]) == record["prediction"] == results[record["demon"]]["prediction"]
        assert record["thesis"] == results[record["demon"]]["thesis"]


def test_exports_of_unknown_things_are_404_and_bad_formats_422(
    client: TestClient, create_run: Callable[..., str]
) -> None:
    assert client.get("/api/runs/nope/export/history").status_code == 404
    assert client.get("/api/runs/nope/export/spec").status_code == 404
    assert client.get("/api/protocols/nope/export").status_code == 404
    run_id = create_run()
    assert client.get(f"/api/runs/{run_id}/export/history", params={"format": "xml"}).status_code == 422
