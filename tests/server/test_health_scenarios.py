"""GET /api/health, GET /api/scenarios, GET /api/scenarios/{name}: read-only, 404, 409 for a broken file."""

from __future__ import annotations

from pathlib import Path

from fastapi.testclient import TestClient

from horde.scenarios import load_scenario, scenario_dir
from horde.server import Settings, create_app
from horde.spec import RunSpec


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


def test_every_scenario_served_is_the_file_that_horde_run_reads(client: TestClient) -> None:
    served = {s["name"] for s in client.get("/api/scenarios").json()}
    files = {path.stem for path in scenario_dir().glob("*.toml")}
    assert served == files
    for name in sorted(files):
        body = client.get(f"/api/scenarios/{name}").json()
        assert RunSpec.model_validate(body) == load_scenario(scenario_dir() / f"{name}.toml"), name


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


def test_a_scenarios_watch_table_is_served_and_checked(tmp_path: Path) -> None:
    folder = tmp_path / "scenarios"
    folder.mkdir()
    (folder / "slow.toml").write_text('description = "slow"\n\n[watch]\nhz = 5\nnote = "see each step"\n')
    (folder / "plain.toml").write_text('description = "plain"\n')
    (folder / "too-slow.toml").write_text('description = "x"\n\n[watch]\nhz = 0\n')
    settings = Settings(data=tmp_path / "data", scenarios=folder, token=None)
    with TestClient(create_app(settings)) as client:
        listed = {s["name"]: s for s in client.get("/api/scenarios").json()}
        assert (listed["slow"]["watch_hz"], listed["slow"]["watch_note"]) == (5, "see each step")
        assert (listed["plain"]["watch_hz"], listed["plain"]["watch_note"]) == (None, "")
        assert "too-slow.toml:4: watch.hz" in listed["too-slow"]["error"]
        assert "watch" not in client.get("/api/scenarios/slow").json()  # no part of the RunSpec
        created = client.post("/api/runs", json={"scenario": "slow"})
        assert created.status_code == 201, created.text


def test_baird_is_watched_fast_enough_to_see_td_diverge_in_about_ten_seconds(client: TestClient) -> None:
    """The README: launch `baird` and watch for ten seconds; td diverges near step 10,000."""
    baird = next(s for s in client.get("/api/scenarios").json() if s["name"] == "baird")
    assert baird["watch_hz"] is not None and 10_000 / baird["watch_hz"] <= 12
