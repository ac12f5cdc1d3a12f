"""POST/GET /api/studies: a study in the background, its progress over REST and the stream, cancel,
resume, results with bands, exports, and every bad axis a 422 before any task starts."""

from __future__ import annotations

import csv
import io
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

from horde.server import Settings
from polling import wait_until
from sockets import receive_json

from .helpers import wait_study

STUDY: dict[str, Any] = {
    "scenario": "classroom-offpolicy",
    "runs": 2,
    "measure": {"episodes": 40, "checkpoints": 2},
    "axes": [{"path": "learning.alpha", "values": [0.03, 0.1]}, {"path": "demons.*.learner", "values": ["td", "gq"]}],
}


@pytest.fixture
def settings(tmp_path: Path) -> Settings:
    return Settings(data=tmp_path / "data", token=None, snapshot_every=3600.0, study_executor="local")


def test_a_study_runs_in_the_background_and_reports_bands(client: TestClient) -> None:
    response = client.post("/api/studies", json=STUDY)
    assert response.status_code == 202, response.text
    started = response.json()
    assert started["tasks"] == 8 and started["configurations"] == 4 and started["scenario"] == "classroom-offpolicy"
    body = wait_study(client, started["id"], "finished")
    assert body["tasks_done"] == 8 and body["episodes"] == 40
    results = body["results"]
    assert [r["axes"] for r in results] == [
        {"learning.alpha": a, "demons.*.learner": learner} for a in (0.03, 0.1) for learner in ("td", "gq")
    ]
    assert sum(r["best"] for r in results) == 1
    for r in results:
        assert r["runs"] == 2 and r["truth"] == "exact" and r["episodes"] == [0, 20, 40]
        assert r["ci_low"] <= r["error"] <= r["ci_high"]
        assert len(r["curve"]["mean"]) == 3 and r["curve"]["mean"][0] == pytest.approx(1.0)  # zero weights
        assert r["returns"]["mean"][0] is None  # no episode before the first checkpoint
        assert set(r["demons"]) == {"steps_northeast", "goal_northeast", "steps_southwest", "goal_southwest",
                                    "steps_random", "goal_random"}  # fmt: skip
    listed = client.get("/api/studies").json()
    assert [s["id"] for s in listed] == [started["id"]] and "results" not in listed[0]


def test_study_results_export_as_csv_and_json(client: TestClient) -> None:
    study_id = client.post("/api/studies", json=STUDY).json()["id"]
    wait_study(client, study_id, "finished")
    as_csv = client.get(f"/api/studies/{study_id}/export", params={"format": "csv"})
    assert as_csv.status_code == 200 and as_csv.headers["content-type"].startswith("text/csv")
    assert "attachment" in as_csv.headers["content-disposition"]
    rows = list(csv.DictReader(io.StringIO(as_csv.text)))
    assert len(rows) == 4 * 7  # per configuration: all demons (*) and each of six
    assert set(rows[0]) >= {"config", "learning.alpha", "demons.*.learner", "runs", "demon", "error", "ci_low"}
    as_json = client.get(f"/api/studies/{study_id}/export", params={"format": "json"}).json()
    detail = client.get(f"/api/studies/{study_id}").json()["results"]
    assert [r["error"] for r in as_json] == [r["error"] for r in detail]
    by_demon = {(int(r["config"]), r["demon"]): float(r["error"]) for r in rows}
    assert by_demon[(0, "goal_random")] == as_json[0]["demons"]["goal_random"]["error"]


@pytest.mark.timeout(120)
def test_a_diverged_configuration_and_gtd_as_td_are_flagged_in_results_and_exports(client: TestClient) -> None:
    study = {
        "scenario": "classroom-offpolicy",
        "runs": 1,
        "measure": {"episodes": 20, "checkpoints": 2},
        "axes": [
            {"path": "learning.alpha", "values": [0.03, 10.0]},  # a step of 10 overshoots tenfold: TD blows up
            {"path": "demons.*.learner", "values": ["td", "gtd"]},
            {"path": "learning.alpha_w", "values": [0.0]},
        ],
    }
    study_id = client.post("/api/studies", json=study).json()["id"]
    body = wait_study(client, study_id, "finished")
    flagged = {(r["axes"]["learning.alpha"], r["axes"]["demons.*.learner"]): r["diverged"] for r in body["results"]}
    assert flagged == {(0.03, "td"): False, (0.03, "gtd"): False, (10.0, "td"): True, (10.0, "gtd"): True}
    assert not any(r["best"] and r["diverged"] for r in body["results"])
    assert len(body["warnings"]) == 1 and "gtd with alpha_w = 0 learns exactly as td" in body["warnings"][0]
    rows = list(csv.DictReader(io.StringIO(client.get(f"/api/studies/{study_id}/export").text)))
    assert {r["config"]: r["diverged"] for r in rows} == {
        str(r["index"]): str(int(r["diverged"])) for r in body["results"]
    }
    curves = client.get(f"/api/studies/{study_id}/export", params={"format": "curves"})
    assert curves.status_code == 200 and "curves.csv" in curves.headers["content-disposition"]
    points = list(csv.DictReader(io.StringIO(curves.text)))
    first = body["results"][0]
    mine = [r for r in points if r["config"] == str(first["index"]) and r["demon"] == "*"]
    assert [int(r["episode"]) for r in mine] == first["episodes"] == [0, 10, 20]
    assert [float(r["error"]) for r in mine] == pytest.approx(first["curve"]["mean"])


def test_the_stream_reports_progress_until_the_study_stops(client: TestClient) -> None:
    study = {**STUDY, "measure": {"episodes": 400, "checkpoints": 2}}
    study_id = client.post("/api/studies", json=study).json()["id"]
    seen = []
    with client.websocket_connect(f"/api/studies/{study_id}/stream") as ws:
        for _ in range(2000):
            message = receive_json(ws, "the study's next progress message")
            seen.append((message["status"], message["tasks_done"]))
            if message["status"] != "running":
                break
    assert seen[-1] == ("finished", 8)
    assert any(status == "running" for status, _ in seen)
    done = [d for _, d in seen]
    assert done == sorted(done)


def test_cancel_keeps_finished_tasks_and_resume_runs_the_rest(client: TestClient) -> None:
    study = {**STUDY, "measure": {"episodes": 600, "checkpoints": 1}}
    study_id = client.post("/api/studies", json=study).json()["id"]
    wait_until(lambda: client.get(f"/api/studies/{study_id}").json()["tasks_done"] >= 1, "a task to finish", 60.0)
    assert client.delete(f"/api/studies/{study_id}").status_code == 200
    cancelled = wait_study(client, study_id, "cancelled")
    kept = cancelled["tasks_done"]
    assert 1 <= kept < 8 and "cancelled after" in cancelled["message"]
    assert client.post(f"/api/studies/{study_id}/resume").status_code == 202
    assert wait_study(client, study_id, "finished")["tasks_done"] == 8
    assert client.post(f"/api/studies/{study_id}/resume").status_code == 409  # nothing left
    assert client.delete(f"/api/studies/{study_id}").status_code == 200  # not running: deleted
    assert client.get(f"/api/studies/{study_id}").status_code == 404


def test_one_study_at_a_time(client: TestClient) -> None:
    slow = {**STUDY, "measure": {"episodes": 3000, "checkpoints": 1}}
    first = client.post("/api/studies", json=slow).json()["id"]
    second = client.post("/api/studies", json=STUDY)
    assert second.status_code == 429 and "one at a time" in second.json()["detail"]
    client.delete(f"/api/studies/{first}")
    wait_study(client, first, "cancelled")


def FORTY(path: str) -> dict[str, Any]:  # noqa: N802 - reads as a constant in the table below
    return {"path": path, "values": [0.001 * i for i in range(1, 41)]}


def forty(path: str) -> dict[str, Any]:
    """An axis of 40 values: two of them make a grid past the bound of 1000 configurations."""
    return {"path": path, "values": [0.001 * i for i in range(1, 41)]}


@pytest.mark.parametrize(
    ("change", "loc", "words"),
    [
        ({"axes": [{"path": "learning.alfa", "values": [0.1]}]}, ["body", "axes", 0, "path"], "learning.alfa"),
        ({"axes": [{"path": "learning.lambda", "values": [0.5, 2]}]}, ["body", "axes", 0, "values", 1], "lambda = 2"),
        ({"axes": [{"path": "demons.*.learner", "values": ["sarsa"]}]}, ["body", "axes", 0, "values", 0], "sarsa"),
        ({"axes": [forty("learning.alpha"), forty("learning.alpha_w")]}, ["body", "axes"], "1600 configurations"),
        ({"axes": [{"path": "seed", "values": [1]}], "runs": 101}, ["body", "runs"], "less than or equal to 100"),
    ],
)
def test_bad_axes_are_a_422_naming_the_axis_before_any_task(
    client: TestClient, change: dict[str, Any], loc: list[Any], words: str
) -> None:
    response = client.post("/api/studies", json={**STUDY, **change})
    assert response.status_code == 422, response.text
    problems = response.json()["detail"]
    assert problems[0]["loc"] == loc and words in problems[0]["msg"]
    assert client.get("/api/studies").json() == []  # nothing stored, nothing started


def test_an_unknown_scenario_or_study_is_a_404(client: TestClient) -> None:
    assert client.post("/api/studies", json={**STUDY, "scenario": "nope"}).status_code == 404
    assert client.get("/api/studies/nope").status_code == 404
    assert client.get("/api/studies/nope/export").status_code == 404


@pytest.mark.slow
def test_the_server_runs_a_study_on_ray(tmp_path: Path) -> None:
    """The server's default executor: Ray on this machine, started from the study's thread."""
    from fastapi.testclient import TestClient as Client

    from horde.server import create_app

    settings = Settings(data=tmp_path / "ray-data", token=None, snapshot_every=3600.0, study_workers=2)
    assert settings.study_executor == "ray"
    with Client(create_app(settings)) as client:
        study_id = client.post("/api/studies", json=STUDY).json()["id"]
        body = wait_study(client, study_id, "finished", timeout=180)
        assert body["tasks_done"] == 8 and len(body["results"]) == 4
