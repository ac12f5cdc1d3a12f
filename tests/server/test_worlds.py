"""GET|POST /api/worlds, GET|PUT|DELETE /api/worlds/{name}, and runs made from a stored world."""

from __future__ import annotations

from fastapi.testclient import TestClient

from horde.server import Settings, create_app

from .helpers import BASE_DEMON, WORLD, locs, messages


def room(name: str = "room", **changes: object) -> dict[str, object]:
    return {**WORLD, "name": name, **changes}


def test_world_life_cycle(client: TestClient) -> None:
    assert client.get("/api/worlds").json() == []
    created = client.post("/api/worlds", json=room())
    assert created.status_code == 201
    assert created.json()["name"] == "room" and created.json()["world"]["width"] == 500
    assert [w["name"] for w in client.get("/api/worlds").json()] == ["room"]
    assert client.get("/api/worlds/room").json()["world"]["regions"][0]["name"] == "goal"
    replaced = client.put("/api/worlds/room", json=room(width=600))
    assert replaced.status_code == 200 and replaced.json()["world"]["width"] == 600
    assert client.delete("/api/worlds/room").status_code == 204
    assert client.get("/api/worlds/room").status_code == 404
    assert client.delete("/api/worlds/room").status_code == 404


def test_put_creates_with_201_and_takes_the_path_name(client: TestClient) -> None:
    body = {k: v for k, v in room().items() if k != "name"}
    response = client.put("/api/worlds/hall", json=body)
    assert response.status_code == 201
    assert response.json()["world"]["name"] == "hall"


def test_duplicate_post_is_409(client: TestClient) -> None:
    assert client.post("/api/worlds", json=room()).status_code == 201
    response = client.post("/api/worlds", json=room())
    assert response.status_code == 409 and "exists" in response.json()["detail"]


def test_invalid_world_is_422_naming_the_field(client: TestClient) -> None:
    assert ["body", "width"] in locs(client.post("/api/worlds", json=room(width=-1)))
    assert ["body", "name"] in locs(client.post("/api/worlds", json={k: v for k, v in room().items() if k != "name"}))
    assert ["body", "colour"] in locs(client.post("/api/worlds", json=room(colour="red")))
    assert "start" in messages(client.post("/api/worlds", json=room(start=[450, 450])))
    response = client.put("/api/worlds/room", json=room(name="other"))
    assert ["body", "name"] in locs(response)
    assert ["path", "name"] in locs(client.put("/api/worlds/bad name!", json=room()))


def test_unknown_world_is_404(client: TestClient) -> None:
    assert client.get("/api/worlds/nowhere").status_code == 404


def test_number_of_worlds_is_bounded(settings: Settings) -> None:
    settings = settings.model_copy(update={"max_worlds": 2})
    with TestClient(create_app(settings)) as client:
        for name in ("a", "b"):
            assert client.post("/api/worlds", json=room(name)).status_code == 201
        assert client.post("/api/worlds", json=room("c")).status_code == 409
        assert client.put("/api/worlds/c", json=room("c")).status_code == 409
        assert client.put("/api/worlds/a", json=room("a")).status_code == 200


def test_a_run_copies_a_stored_world_by_name(client: TestClient) -> None:
    client.post("/api/worlds", json=room(max_steps=7))
    body = {"world": "room", "demons": [BASE_DEMON], "behaviour": {"kind": "softmax", "demon": "base"}}
    response = client.post("/api/runs", json=body)
    assert response.status_code == 201, response.text
    assert response.json()["spec"]["world"]["max_steps"] == 7
    client.delete("/api/worlds/room")
    run_id = response.json()["id"]
    assert client.get(f"/api/runs/{run_id}").json()["spec"]["world"]["max_steps"] == 7


def test_a_run_from_an_unknown_world_is_404(client: TestClient) -> None:
    response = client.post("/api/runs", json={"world": "nowhere"})
    assert response.status_code == 404 and "nowhere" in response.json()["detail"]
