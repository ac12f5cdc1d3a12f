"""HORDE_TOKEN: every mutating request needs the bearer token (401 otherwise); reads do not."""

from __future__ import annotations

import re
from pathlib import Path

from fastapi.testclient import TestClient

from horde.server import Settings, create_app
from horde.server.cli_serve import security_warning

from .helpers import make_spec


def test_mutating_requests_need_the_token(tmp_path: Path) -> None:
    settings = Settings(data=tmp_path, token="s3cret")
    with TestClient(create_app(settings)) as client:
        assert client.post("/api/runs", json=make_spec()).status_code == 401
        wrong = client.post("/api/runs", json=make_spec(), headers={"Authorization": "Bearer nope"})
        assert wrong.status_code == 401 and wrong.headers["www-authenticate"] == "Bearer"
        good = {"Authorization": "Bearer s3cret"}
        created = client.post("/api/runs", json=make_spec(), headers=good)
        assert created.status_code == 201
        run_id = created.json()["id"]
        for method, path in [
            ("post", f"/api/runs/{run_id}/step"),
            ("post", f"/api/runs/{run_id}/start"),
            ("patch", f"/api/runs/{run_id}"),
            ("delete", f"/api/runs/{run_id}/demons/steps"),
            ("put", "/api/worlds/w"),
            ("delete", f"/api/runs/{run_id}"),
        ]:
            assert client.request(method, path, json={}).status_code == 401, (method, path)
        assert client.get("/api/runs").status_code == 200
        assert client.get(f"/api/runs/{run_id}/state").status_code == 200
        assert client.get(f"/api/runs/{run_id}/snapshot").status_code == 200
        assert client.delete(f"/api/runs/{run_id}", headers=good).status_code == 204


def test_no_token_no_check(client: TestClient) -> None:
    assert client.post("/api/runs", json=make_spec()).status_code == 201


def test_the_token_is_documented_in_the_openapi_schema(client: TestClient) -> None:
    schema = client.get("/openapi.json").json()
    assert "HTTPBearer" in schema["components"]["securitySchemes"]
    assert "401" in schema["paths"]["/api/runs"]["post"]["responses"]
    assert "401" not in schema["paths"]["/api/runs"]["get"]["responses"]


def test_binding_beyond_loopback_without_a_token_warns() -> None:
    assert security_warning(Settings(host="0.0.0.0", token=None)) is not None
    assert security_warning(Settings(host="0.0.0.0", token="t")) is None
    assert security_warning(Settings(host="127.0.0.1", token=None)) is None
    assert security_warning(Settings(host="localhost", token=None)) is None
    assert security_warning(Settings(host="::1", token=None)) is None


def test_every_route_that_changes_something_needs_the_token(tmp_path: Path) -> None:
    """Read from the OpenAPI schema, so a write route registered on a reading router fails here: every POST,
    PUT, PATCH and DELETE answers 401 without the token, before it looks at its path or body."""
    with TestClient(create_app(Settings(data=tmp_path, token="s3cret"))) as client:
        paths = client.get("/openapi.json").json()["paths"]
        writes = [(method, path) for path, item in paths.items() for method in item if method != "get"]
        writes.remove(("post", "/api/view"))  # a tab's own choice of what it watches: no token needed
        assert len(writes) >= 20, writes
        for method, path in writes:
            response = client.request(method, re.sub(r"\{\w+\}", "x", path), json={})
            assert response.status_code == 401, (method, path, response.text)
