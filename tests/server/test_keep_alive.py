"""An idle kept-alive connection is the client's to close: the server keeps it open past httpx's idle expiry,
so a pooled client never sends a request into a connection the server is closing (a reset, seen in CI)."""

from __future__ import annotations

import http.client
import select
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest

from horde.server import Settings
from serving import RunningServer, serve_in_thread

# httpx closes a pooled connection idle this long itself, before its next request.
CLIENT_IDLE_EXPIRY = httpx.Limits().keepalive_expiry or 5.0


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[RunningServer]:
    data: Path = tmp_path_factory.mktemp("keep-alive") / "data"
    with serve_in_thread(Settings(data=data, token=None, snapshot_every=3600.0)) as running:
        yield running


def test_an_idle_connection_outlives_the_clients_expiry_and_serves_again(server: RunningServer) -> None:
    host, port = server.url.removeprefix("http://").split(":")
    conn = http.client.HTTPConnection(host, int(port), timeout=30)
    try:
        conn.request("GET", "/api/health")
        assert conn.getresponse().read() and conn.sock is not None
        kept = conn.sock
        # The connection stays quiet (a close or a reset would make it readable) for longer than the client keeps it
        # in its pool.
        readable, _, _ = select.select([kept], [], [], CLIENT_IDLE_EXPIRY + 2.0)
        assert not readable, f"the server ended an idle connection within {CLIENT_IDLE_EXPIRY + 2.0} s"
        conn.request("GET", "/api/health")
        assert conn.getresponse().status == 200 and conn.sock is kept, "the second request took a new connection"
    finally:
        conn.close()
