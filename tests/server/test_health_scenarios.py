"""GET /api/health, GET /api/scenarios, GET /api/scenarios/{name}: read-only, 404, 409 for a broken file."""

from __future__ import annotations

from pathlib import Path

from fastapi.testclient import TestClient

from horde.server import Settings, create_app


def test_health(client: TestClient) -> None:
    body = client.get("/api/health").json()
    assert body["status"] == "ok" and body["runs"] == 0


def test_scenarios_list_and_get(client: TestClient) -> None:
    names = {s["name"] for s in client.get("/api/scenarios").json()}
    assert "experiment1" in names
    spec = client.get("/api/scenarios/experiment1").json()
    assert {d["name"] for d in spec["demons"]} >= {"base", "steps_to_end"}


def test_unknown_scenario_is_404(client: TestClient) -> None:
    response = client.get("/api/scenarios/no-such-scenario")
    assert response.status_code == 404
    assert "no-such-scenario" in response.json()["detail"]


def test_scenarios_are_read_only(client: TestClient) -> None:
    assert client.post("/api/scenarios", json={}).status_code == 405
    assert client.put("/api/scenarios/experiment1", json={}).status_code == 405
    assert client.delete("/api/scenarios/experiment1").status_code == 405


def test_broken_scenario_file_is_listed_with_its_error_and_409(tmp_path: Path) -> None:
    folder = tmp_path / "scenarios"
    folder.mkdir()
    (folder / "good.toml").write_text('description = "fine"\n')
    (folder / "broken.toml").write_text("[world]\nwidth = -5\n")
    settings = Settings(data=tmp_path / "data", scenarios=folder, token=None)
    with TestClient(create_app(settings)) as client:
        listed = {s["name"]: s for s in client.get("/api/scenarios").json()}
        assert listed["good"]["error"] is None and listed["good"]["description"] == "fine"
        assert "width" in listed["broken"]["error"]
        response = client.get("/api/scenarios/broken")
        assert response.status_code == 409
        assert "width" in response.json()["detail"]
