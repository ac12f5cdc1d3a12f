"""WS /api/streams/{id}/records closes with the codes of server/stream_protocol.py's StreamClose (the one
source the dashboard's are generated from): unknown stream run, no token, the stream run deleted meanwhile."""

from __future__ import annotations

from pathlib import Path

import pytest
from fastapi.testclient import TestClient
from starlette.websockets import WebSocketDisconnect

from horde.server import Settings, create_app
from horde.server.stream_protocol import StreamClose
from sockets import receive_json

from .test_stream_history import records, spec


def test_an_unknown_stream_run_closes_with_not_found(client: TestClient) -> None:
    with client.websocket_connect("/api/streams/nope/records") as ws, pytest.raises(WebSocketDisconnect) as closed:
        receive_json(ws, "the not-found close")  # accepted, then closed: the client sees the code
    assert closed.value.code == StreamClose.NOT_FOUND == 4404


def test_pushing_without_the_token_closes_with_unauthorized(tmp_path: Path) -> None:
    with TestClient(create_app(Settings(data=tmp_path, token="s3cret", snapshot_every=3600.0))) as client:
        headers = {"Authorization": "Bearer s3cret"}
        stream = client.post("/api/streams", json=spec(), headers=headers).json()["id"]
        url = f"/api/streams/{stream}/records"
        with client.websocket_connect(url) as ws, pytest.raises(WebSocketDisconnect) as closed:
            receive_json(ws, "the unauthorized close")
        assert closed.value.code == StreamClose.UNAUTHORIZED == 4401
        with client.websocket_connect(f"{url}?token=s3cret") as ws:
            assert receive_json(ws, "the hello")["type"] == "hello"


def test_a_stream_run_deleted_while_pushing_closes_with_run_deleted(client: TestClient) -> None:
    stream = client.post("/api/streams", json=spec()).json()["id"]
    with client.websocket_connect(f"/api/streams/{stream}/records") as ws:
        receive_json(ws, "the hello")  # hello
        ws.send_json({"records": records(5)})
        assert receive_json(ws, "the learned count")["learned"] == 5
        assert client.delete(f"/api/streams/{stream}").status_code == 204
        ws.send_json({"records": records(5, 5)})
        with pytest.raises(WebSocketDisconnect) as closed:
            receive_json(ws, "the run-deleted close")
    assert closed.value.code == StreamClose.RUN_DELETED == 4410
    assert "was deleted" in (closed.value.reason or "")
