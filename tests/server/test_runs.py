"""GET|POST /api/runs, GET|PATCH|DELETE /api/runs/{id}: creation forms, limits and errors."""

from __future__ import annotations

from collections.abc import Callable

import pytest
from fastapi.testclient import TestClient

from horde.server import Settings, create_app
from horde.server.schemas import RunTemplateIn
from horde.spec import RunSpec
from polling import wait_until

from .helpers import locs, make_spec, messages


def test_create_list_get_delete(client: TestClient) -> None:
    response = client.post("/api/runs", json=make_spec())
    assert response.status_code == 201
    run = response.json()
    assert run["status"] == "created" and run["step"] == 0 and run["demons"] == ["base", "steps"]
    assert run["spec"]["seed"] == 3 and run["summary"] is None
    assert [r["id"] for r in client.get("/api/runs").json()] == [run["id"]]
    assert client.get(f"/api/runs/{run['id']}").json()["spec"]["demons"][1]["name"] == "steps"
    assert client.delete(f"/api/runs/{run['id']}").status_code == 204
    assert client.get(f"/api/runs/{run['id']}").status_code == 404
    assert client.delete(f"/api/runs/{run['id']}").status_code == 404
    assert client.get("/api/runs").json() == []


@pytest.mark.timeout(60)
def test_an_empty_run_starts_moves_and_takes_demons(client: TestClient) -> None:
    """`{}` (the default RunSpec, no demons) and a run without episodes both start; a demon joins and learns."""
    created = client.post("/api/runs", json={})
    assert created.status_code == 201, created.text
    assert created.json()["demons"] == []
    assert (
        client.post(f"/api/runs/{created.json()['id']}/demons", json={"name": "one", "cumulant": 1}).status_code == 201
    )

    response = client.post("/api/runs", json={"protocol": {"episodes": 0}}, params={"start": "true"})
    assert response.status_code == 201, response.text
    run_id = response.json()["id"]
    wait_until(lambda: client.get(f"/api/runs/{run_id}/state").json()["step"] > 0, "the empty run to move")
    assert client.post(f"/api/runs/{run_id}/demons", json={"name": "one", "cumulant": 1}).status_code == 201
    wait_until(
        lambda: (client.get(f"/api/runs/{run_id}/state").json()["predictions"].get("one") or 0) > 0.5,
        "the demon that joined to learn",
    )
    client.post(f"/api/runs/{run_id}/pause")


def test_create_from_a_scenario_with_overrides(client: TestClient) -> None:
    body = {"scenario": "experiment1", "seed": 9, "protocol": {"episodes": 3}, "world": {"max_steps": 50}}
    response = client.post("/api/runs", json=body)
    assert response.status_code == 201, response.text
    spec = response.json()["spec"]
    assert spec["seed"] == 9 and spec["protocol"]["episodes"] == 3
    assert spec["world"]["max_steps"] == 50 and len(spec["world"]["regions"]) == 3  # merged, not replaced
    assert spec["name"] == "experiment1"


def test_a_template_overrides_every_field_of_a_runspec(client: TestClient) -> None:
    assert set(RunSpec.model_fields) <= set(RunTemplateIn.model_fields)
    family = {
        "name": "bump_g{gamma}",
        "over": {"gamma": [0.5, 0.9]},
        "demon": {"learner": "td", "policy": "uniform", "cumulant": {"sensor": "bump"}, "discount": "{gamma}"},
    }
    scenario = client.get("/api/scenarios/classroom-offpolicy").json()
    response = client.post("/api/runs", json={"scenario": "classroom-offpolicy", "families": [family]})
    assert response.status_code == 201, response.text
    own = [d["name"] for d in scenario["demons"]]
    assert response.json()["demons"] == [*own, "bump_g0.5", "bump_g0.9"]  # the family joins the scenario's demons


def test_create_and_start_at_once_with_hz(client: TestClient) -> None:
    response = client.post("/api/runs", json=make_spec(), params={"start": "true", "hz": 20})
    assert response.status_code == 201
    assert response.json()["status"] == "running" and response.json()["hz"] == 20


def test_unknown_scenario_is_404(client: TestClient) -> None:
    response = client.post("/api/runs", json={"scenario": "nope"})
    assert response.status_code == 404 and "nope" in response.json()["detail"]


def test_invalid_fields_are_422_naming_the_field(client: TestClient) -> None:
    spec = make_spec()
    spec["protocol"] = {"episodes": -1}
    assert ["body", "RunSpec", "protocol", "episodes"] in locs(client.post("/api/runs", json=spec))
    template = {"scenario": "experiment1", "protocol": {"episodes": -1}}
    assert ["body", "protocol", "episodes"] in locs(client.post("/api/runs", json=template))
    typo = {"scenario": "experiment1", "protocoll": {}}
    assert ["body", "RunTemplate", "protocoll"] in locs(client.post("/api/runs", json=typo))
    assert ["query", "hz"] in locs(client.post("/api/runs", json=make_spec(), params={"hz": 0}))


def test_cross_field_errors_are_422_with_a_clear_message(client: TestClient) -> None:
    unknown = make_spec(demons=[{"name": "a", "cumulant": {"prediction": "ghost"}}], behaviour="uniform")
    assert "refers to unknown demon 'ghost'" in messages(client.post("/api/runs", json=unknown))
    cycle = make_spec(
        demons=[
            {"name": "a", "cumulant": {"prediction": "b"}},
            {"name": "b", "cumulant": {"prediction": "a"}},
        ],
        behaviour="uniform",
    )
    assert "cycle" in messages(client.post("/api/runs", json=cycle))
    template = {"scenario": "experiment1", "behaviour": {"kind": "greedy", "demon": "nobody"}}
    assert "unknown demon 'nobody'" in messages(client.post("/api/runs", json=template))


def test_sizes_beyond_the_servers_limits_are_422(settings: Settings) -> None:
    settings = settings.model_copy(update={"max_demons": 1})
    with TestClient(create_app(settings)) as client:
        response = client.post("/api/runs", json=make_spec())
        assert ["body", "demons"] in locs(response)
        assert "at most 1 demons" in messages(response)


def test_number_of_runs_is_bounded(settings: Settings) -> None:
    settings = settings.model_copy(update={"max_runs": 2})
    with TestClient(create_app(settings)) as client:
        for _ in range(2):
            assert client.post("/api/runs", json=make_spec()).status_code == 201
        response = client.post("/api/runs", json=make_spec())
        assert response.status_code == 409 and "at most 2 runs" in response.json()["detail"]


def test_patch_speed_and_behaviour(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run()
    assert client.patch(f"/api/runs/{run_id}", json={"hz": 5}).json()["hz"] == 5
    assert client.patch(f"/api/runs/{run_id}", json={}).json()["hz"] == 5  # left out: unchanged
    assert client.patch(f"/api/runs/{run_id}", json={"hz": None}).json()["hz"] is None
    patched = client.patch(f"/api/runs/{run_id}", json={"behaviour": "uniform"}).json()
    assert patched["spec"]["behaviour"]["kind"] == "uniform"


def test_patch_errors(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run()
    assert client.patch("/api/runs/nope", json={"hz": 5}).status_code == 404
    assert ["body", "hz"] in locs(client.patch(f"/api/runs/{run_id}", json={"hz": 0}))
    assert ["body", "speed"] in locs(client.patch(f"/api/runs/{run_id}", json={"speed": 1}))
    response = client.patch(f"/api/runs/{run_id}", json={"behaviour": {"kind": "greedy", "demon": "ghost"}})
    assert "unknown demon 'ghost'" in messages(response)
    assert client.get(f"/api/runs/{run_id}").json()["spec"]["behaviour"]["demon"] == "base"  # nothing lost
