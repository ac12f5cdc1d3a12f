"""GET|POST /api/view: the viser live view inside the server, started by the lifespan when asked for."""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest

with warnings.catch_warnings():
    warnings.filterwarnings("ignore", message=".*install `httpx2`")
    from fastapi.testclient import TestClient

from horde.server import Settings, create_app
from polling import wait_until
from serving import free_port

from .helpers import make_spec


@pytest.fixture
def viewing(tmp_path: Path) -> Iterator[tuple[TestClient, list[str]]]:
    announced: list[str] = []
    settings = Settings(data=tmp_path / "data", token=None, viser_port=free_port(), snapshot_every=3600.0)
    with TestClient(create_app(settings, announced.append)) as client:
        yield client, announced


def test_the_view_is_off_unless_asked_for(client: TestClient) -> None:
    response = client.get("/api/view")
    assert response.status_code == 200
    assert response.json() == {"enabled": False, "url": None, "run": None}
    refused = client.post("/api/view", json={"run": "abc"})
    assert refused.status_code == 409
    assert "live view is off" in refused.json()["detail"]


def test_the_view_listens_where_it_says_and_shows_the_chosen_run(viewing: tuple[TestClient, list[str]]) -> None:
    client, announced = viewing
    view = client.get("/api/view").json()
    assert view["enabled"] is True
    assert announced == [view["url"]], "serve prints the address the view really listens on"
    assert view["url"].startswith("http://127.0.0.1:")
    page = httpx.get(view["url"], timeout=10)
    assert page.status_code == 200 and "<html" in page.text.lower()

    first = client.post("/api/runs", json=make_spec()).json()["id"]
    second = client.post("/api/runs", json=make_spec()).json()["id"]
    response = client.post("/api/view", json={"run": second})
    assert response.status_code == 200
    assert response.json()["run"] == second
    wait_until(lambda: client.get("/api/view").json()["run"] == second, "GET /api/view to name the run shown", 5.0)
    assert client.post("/api/view", json={"run": first}).json()["run"] == first


def test_showing_an_unknown_run_is_404_and_a_bad_body_422(viewing: tuple[TestClient, list[str]]) -> None:
    client, _ = viewing
    assert client.post("/api/view", json={"run": "nope"}).status_code == 404
    response = client.post("/api/view", json={"run": "x", "colour": 1})
    assert response.status_code == 422
    assert response.json()["detail"][0]["loc"][-1] == "colour"
