"""The streams' wire format has one source (server/stream_protocol.py): the codes the server closes with,
the schema the dashboard's types and constants are generated from, and the messages it documents."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import pytest
from fastapi import FastAPI
from fastapi.testclient import TestClient
from starlette.websockets import WebSocketDisconnect

from horde.server.stream_protocol import StreamClose, add_stream_schemas
from sockets import receive_json

GENERATED = Path(__file__).resolve().parents[2] / "frontend" / "src" / "api" / "stream-protocol.ts"


def test_the_schema_names_every_close_code_and_documents_the_messages(client: TestClient) -> None:
    schemas = client.get("/openapi.json").json()["components"]["schemas"]
    close = schemas["StreamClose"]
    assert dict(zip(close["x-enum-varnames"], close["enum"], strict=True)) == {c.name: c.value for c in StreamClose}
    assert len(close["x-enum-descriptions"]) == len(StreamClose) and all(close["x-enum-descriptions"])
    assert schemas["RunStreamMessage"]["$ref"] == "#/components/schemas/StateOut"
    assert schemas["StudyStreamMessage"]["$ref"] == "#/components/schemas/StudyOut"
    # The message a run's stream sends is the model the schema names (its `type` tells it apart).
    assert schemas["StateOut"]["properties"]["type"]["const"] == "state"


def test_the_dashboards_close_codes_are_the_servers() -> None:
    """The committed generated module holds exactly the server's codes (a stale one fails here by name)."""
    text = GENERATED.read_text()
    assert dict(re.findall(r"^\s+([A-Z_]+): (\d+),$", text, re.M)) == {c.name: str(c.value) for c in StreamClose}


def test_an_unknown_run_and_an_unknown_study_close_with_not_found(client: TestClient) -> None:
    for path in ("/api/runs/nope/stream", "/api/studies/nope/stream"):
        with client.websocket_connect(path) as ws, pytest.raises(WebSocketDisconnect) as closed:
            receive_json(ws, "the not-found close")
        assert closed.value.code == StreamClose.NOT_FOUND, path


def test_a_run_streams_messages_the_schema_describes(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run()
    state = client.get(f"/api/runs/{run_id}/state").json()
    with client.websocket_connect(f"/api/runs/{run_id}/stream") as ws:
        message = receive_json(ws, "the first state")
    assert set(message) == set(state)


def test_a_message_naming_a_model_no_route_documents_is_refused() -> None:
    app = FastAPI()  # no routes: neither StateOut nor StudyOut is in its schema
    add_stream_schemas(app)
    with pytest.raises(RuntimeError, match="RunStreamMessage refers to StateOut"):
        app.openapi()
