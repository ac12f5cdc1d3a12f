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
from serving import free_port

from .helpers import make_spec


@pytest.fixture
def viewing(tmp_path: Path) -> Iterator[tuple[TestClient, list[str]]]:
    announced: list[str] = []
    settings = Settings(data=tmp_path / "data", token=None, viser_port=free_port(), snapshot_every=3600.0)
    with TestClient(create_app(settings, announced.append)) as client:
        yield client, announced


TAB, OTHER_TAB = "dashboard-tab-1", "dashboard-tab-2"  # two dashboard tabs' keys


def test_the_view_is_off_unless_asked_for(client: TestClient) -> None:
    response = client.get("/api/view")
    assert response.status_code == 200
    assert response.json() == {"enabled": False, "url": None, "run": None, "browsers": 0, "frame_rate": 0.0}
    refused = client.post("/api/view", json={"viewer": TAB, "run": "abc"})
    assert refused.status_code == 409
    assert "live view is off" in refused.json()["detail"]


def test_the_view_listens_where_it_says_and_shows_each_tab_its_run(viewing: tuple[TestClient, list[str]]) -> None:
    client, announced = viewing
    view = client.get("/api/view").json()
    assert view["enabled"] is True and view["run"] is None, "no tab named: no run to name"
    assert announced == [view["url"]], "serve prints the address the view really listens on"
    assert view["url"].startswith("http://127.0.0.1:")
    page = httpx.get(view["url"], timeout=10)
    assert page.status_code == 200 and "<html" in page.text.lower()
    mine = client.get("/api/view", params={"viewer": TAB}).json()
    socket = f"ws://127.0.0.1:{view['url'].rstrip('/').rsplit(':', 1)[1]}/?viewer={TAB}"
    assert httpx.URL(mine["url"]).params["websocket"] == socket, "the tab's browsers connect with its key"

    first = client.post("/api/runs", json=make_spec()).json()["id"]
    second = client.post("/api/runs", json=make_spec()).json()["id"]
    response = client.post("/api/view", json={"viewer": TAB, "run": second})
    assert response.status_code == 200
    assert response.json()["run"] == second
    assert client.post("/api/view", json={"viewer": OTHER_TAB, "run": first}).json()["run"] == first
    assert client.get("/api/view", params={"viewer": TAB}).json()["run"] == second, "the other tab changed nothing"
    assert client.get("/api/view", params={"viewer": OTHER_TAB}).json()["run"] == first


def test_showing_an_unknown_run_is_404_and_a_bad_body_422(viewing: tuple[TestClient, list[str]]) -> None:
    client, _ = viewing
    assert client.post("/api/view", json={"viewer": TAB, "run": "nope"}).status_code == 404
    response = client.post("/api/view", json={"viewer": TAB, "run": "x", "colour": 1})
    assert response.status_code == 422
    assert response.json()["detail"][0]["loc"][-1] == "colour"
    for bad in ("short", "no spaces here", "x" * 65):
        response = client.post("/api/view", json={"viewer": bad, "run": "x"})
        assert response.status_code == 422 and response.json()["detail"][0]["loc"] == ["body", "viewer"], bad
        response = client.get("/api/view", params={"viewer": bad})
        assert response.status_code == 422 and response.json()["detail"][0]["loc"] == ["query", "viewer"], bad
    missing = client.post("/api/view", json={"run": "x"})
    assert missing.status_code == 422 and missing.json()["detail"][0]["loc"] == ["body", "viewer"]


def test_choosing_what_a_tab_sees_needs_no_token(tmp_path: Path) -> None:
    """It changes no run and nothing another browser sees: a viewer may choose what it watches."""
    settings = Settings(data=tmp_path / "data", token="s3cret", viser_port=free_port(), snapshot_every=3600.0)
    with TestClient(create_app(settings)) as client:
        run = client.post("/api/runs", json=make_spec(), headers={"Authorization": "Bearer s3cret"}).json()["id"]
        assert client.post("/api/view", json={"viewer": TAB, "run": run}).status_code == 200


def test_a_tabs_token_goes_to_its_view_and_a_wrong_one_is_401(tmp_path: Path) -> None:
    """The token sent with a tab's choice is what its embedded view acts with (see tests/view/test_view_roles.py
    for what that view then offers); a wrong or revoked one is refused, as on every route."""
    settings = Settings(data=tmp_path / "data", token="s3cret", viser_port=free_port(), snapshot_every=3600.0)
    teacher = {"Authorization": "Bearer s3cret"}
    with TestClient(create_app(settings)) as client:
        run = client.post("/api/runs", json=make_spec(), headers=teacher).json()["id"]
        alice = client.post("/api/tokens", json={"role": "student", "name": "alice"}, headers=teacher).json()
        body = {"viewer": TAB, "run": run, "large": True}
        assert client.post("/api/view", json=body, headers={"Authorization": f"Bearer {alice['token']}"}).is_success
        choice = client.app.state.live_view._choices[TAB]  # type: ignore[attr-defined]
        assert (choice.run, choice.large, choice.secret) == (run, True, alice["token"])
        assert client.post("/api/view", json=body, headers={"Authorization": "Bearer nope"}).status_code == 401
        client.delete(f"/api/tokens/{alice['id']}", headers=teacher)
        revoked = client.post("/api/view", json=body, headers={"Authorization": f"Bearer {alice['token']}"})
        assert revoked.status_code == 401 and "revoked" in revoked.json()["detail"]
