"""A start rectangle with no free cell is a 422 at world.start over REST (the spec's rule, tests/core/test_spec.py)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from fastapi.testclient import TestClient

from horde.server import Settings, create_app
from horde.spec import IMPOSSIBLE_START

WALLED: dict[str, Any] = {
    "start": [100, 200, 200, 300],
    "regions": [{"name": "wall", "kind": "obstacle", "rect": [100, 200, 200, 300]}],
}


def test_an_impossible_start_is_a_422_naming_world_start(tmp_path: Path) -> None:
    settings = Settings(data=tmp_path / "data", token=None, snapshot_every=3600.0, history=2000, max_runs=2)
    with TestClient(create_app(settings)) as client:
        body: dict[str, Any] = {"name": "walled", "world": WALLED, "demons": [{"name": "a"}]}
        response = client.post("/api/runs", json=body)
        assert response.status_code == 422, response.text
        errors = response.json()["detail"]
        assert [e["loc"][-2:] for e in errors] == [["world", "start"]], errors
        assert errors[0]["msg"] == IMPOSSIBLE_START
        # The same world with one free column (x in [190, 200)) is accepted.
        body["world"] = {**WALLED, "regions": [{**WALLED["regions"][0], "rect": [100, 200, 190, 300]}]}
        assert client.post("/api/runs", json=body).status_code == 201
