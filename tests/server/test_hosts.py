"""DNS rebinding: every route (REST, the dashboard's files, WebSocket upgrades) answers only requests whose
`Host` names this server (server/hosts.py), on a real server and in process."""

from __future__ import annotations

import socket
from collections.abc import Iterator
from pathlib import Path

import pytest
import websockets.sync.client as ws_client
from fastapi.testclient import TestClient
from websockets.exceptions import ConnectionClosed

from horde.server import Settings, create_app
from horde.server.hosts import HostRule
from serving import RunningServer, health_is_quick, serve_in_thread

EVIL = "rebind.evil.example"


def test_the_host_rule() -> None:
    loopback = HostRule.of("127.0.0.1", [])
    for host in ("127.0.0.1:8000", "localhost", "LOCALHOST.:8000", "[::1]:8000", "lab.localhost:8000", None):
        assert loopback.allows(host), host
    for host in (f"{EVIL}:8000", "testserver", f"{EVIL}@127.0.0.1", "127.0.0.1:port", "", "192.0.2.2:8000"):
        assert not loopback.allows(host), host
    assert HostRule.of("127.0.0.1", ["lab.school.example"]).allows("LAB.school.example:8000")
    assert HostRule.of("127.0.0.1", ["*"]).allows(f"{EVIL}:8000")
    every = HostRule.of("0.0.0.0", [])
    assert every.allows("192.0.2.2:8000") and every.allows("[fe80::1]:8000"), "an address is never a rebound name"
    assert not every.allows(f"{EVIL}:8000")
    assert HostRule.of("lab.school.example", []).allows("lab.school.example:8000"), "the bound name"


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[RunningServer]:
    settings = Settings(data=tmp_path_factory.mktemp("hosts") / "data", token=None, snapshot_every=3600.0)
    with serve_in_thread(settings) as running:
        yield running


@pytest.mark.serial  # /api/health within 100 ms: a bound on time
def test_a_rebound_name_cannot_change_or_read_anything(server: RunningServer) -> None:
    port = server.url.rsplit(":", 1)[1]
    rebound = {"host": f"{EVIL}:{port}"}
    world = server.client.put("/api/worlds/x", json={"name": "x"}, headers=rebound)
    assert world.status_code == 400, world.text
    detail = world.json()["detail"]
    assert EVIL in detail and "HORDE_ALLOWED_HOSTS" in detail
    health_is_quick(server)
    assert server.client.get("/api/worlds/x").status_code == 404, "nothing was created"
    for path in ("/api/runs", "/", "/openapi.json", "/docs"):
        assert server.client.get(path, headers=rebound).status_code == 400, path
        health_is_quick(server)
    assert server.client.get("/api/runs", headers={"host": f"localhost:{port}"}).status_code == 200


@pytest.mark.serial  # /api/health within 100 ms: a bound on time
def test_a_rebound_name_cannot_open_a_websocket(server: RunningServer) -> None:
    port = server.url.rsplit(":", 1)[1]
    tcp = socket.create_connection(("127.0.0.1", int(port)), timeout=10)  # the rebound name, resolved
    with (
        ws_client.connect(f"ws://{EVIL}:{port}/api/runs/nope/stream", sock=tcp, open_timeout=10) as ws,
        pytest.raises(ConnectionClosed) as closed,
    ):
        ws.recv(timeout=10)
    assert closed.value.rcvd is not None and closed.value.rcvd.code == 1008
    assert "HORDE_ALLOWED_HOSTS" in closed.value.rcvd.reason
    health_is_quick(server)


def test_the_default_allows_no_other_name(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("HORDE_ALLOWED_HOSTS")  # tests/conftest.py allows the test client's name
    with TestClient(create_app(Settings(data=tmp_path, token=None))) as client:
        refused = client.get("/api/health")
        assert refused.status_code == 400 and "'testserver'" in refused.json()["detail"]
        assert client.get("/api/health", headers={"host": "127.0.0.1:8000"}).status_code == 200
