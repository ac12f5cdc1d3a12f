"""tests/sockets.py's bounded reads: they fail in time when nothing arrives, and lose no message."""

from __future__ import annotations

import time

import pytest
from starlette.applications import Starlette
from starlette.routing import WebSocketRoute
from starlette.testclient import TestClient
from starlette.websockets import WebSocket, WebSocketDisconnect

from sockets import receive_json, receive_text


async def echo_later(websocket: WebSocket) -> None:
    """Accept, then answer each text frame with {"echo": text}; close on "close"."""
    await websocket.accept()
    while (text := await websocket.receive_text()) != "close":
        await websocket.send_json({"echo": text})
    await websocket.close(code=4001)


APP = Starlette(routes=[WebSocketRoute("/ws", echo_later)])


def test_a_read_with_nothing_to_read_fails_within_its_bound() -> None:
    with TestClient(APP) as client, client.websocket_connect("/ws") as ws:
        began = time.monotonic()
        with pytest.raises(AssertionError, match=r"waited 0\.5 s on the WebSocket for the echo"):
            receive_json(ws, "the echo", timeout=0.5)
        assert 0.5 <= time.monotonic() - began < 3.0
        ws.send_text("hello")  # the cancelled read took nothing: the next one gets the answer
        assert receive_json(ws, "the echo") == {"echo": "hello"}
        ws.send_text("close")
        with pytest.raises(WebSocketDisconnect) as closed:
            receive_text(ws, "the close")
        assert closed.value.code == 4001
