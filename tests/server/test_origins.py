"""WebSocket upgrades accept only the server's own pages (their Origin), never another site's (the live view's
port: tests/e2e/test_view_auth_e2e.py)."""

from __future__ import annotations

from pathlib import Path

import pytest
from fastapi.testclient import TestClient
from starlette.websockets import WebSocketDisconnect

from horde.server import Settings, create_app
from horde.server.hosts import HostRule
from horde.server.origins import origin_allowed
from sockets import receive_json

from .helpers import make_spec

LOOPBACK = HostRule.of("127.0.0.1", [])


def test_origin_rules() -> None:
    assert origin_allowed(None, "127.0.0.1:8000", LOOPBACK), "no Origin: not a browser page"
    assert origin_allowed("http://127.0.0.1:8000", "127.0.0.1:8000", LOOPBACK)
    assert origin_allowed("http://localhost:8080/", "localhost:8080", LOOPBACK)
    assert origin_allowed("http://[::1]:8000", "[::1]:8000", LOOPBACK)
    assert not origin_allowed("http://evil.example", "127.0.0.1:8000", LOOPBACK), "another site"
    assert not origin_allowed("http://127.0.0.1:9999", "127.0.0.1:8000", LOOPBACK), "another port"
    assert not origin_allowed("null", "127.0.0.1:8000", LOOPBACK), "a sandboxed page"
    # DNS rebinding: the attacker's name points at 127.0.0.1; Origin and Host agree, but not a loopback name.
    assert not origin_allowed("http://evil.example:8000", "evil.example:8000", LOOPBACK)
    served_openly = HostRule.of("0.0.0.0", ["lab.school.example"])
    assert origin_allowed("http://lab.school.example:8000", "lab.school.example:8000", served_openly)
    assert not origin_allowed("http://evil.example:8000", "evil.example:8000", served_openly)
    assert origin_allowed("http://localhost:5173", "127.0.0.1:8000", LOOPBACK, ["http://localhost:5173/"])


def test_the_stream_refuses_other_sites(tmp_path: Path) -> None:
    with TestClient(create_app(Settings(data=tmp_path, token=None, snapshot_every=3600.0))) as client:
        run = client.post("/api/runs", json=make_spec()).json()["id"]
        own = {"origin": "http://127.0.0.1:8000", "host": "127.0.0.1:8000"}
        with client.websocket_connect(f"/api/runs/{run}/stream", headers=own) as ws:
            assert receive_json(ws, "the first state from the own origin")["run"] == run
        with client.websocket_connect(f"/api/runs/{run}/stream") as ws:  # no Origin: a script, not a page
            assert receive_json(ws, "the first state without an Origin")["run"] == run
        other = {**own, "origin": "http://evil.example"}
        with (
            client.websocket_connect(f"/api/runs/{run}/stream", headers=other) as ws,
            pytest.raises(WebSocketDisconnect) as refused,
        ):
            receive_json(ws, "the close of another site's stream")  # accepted, then closed before any message
        assert refused.value.code == 1008
