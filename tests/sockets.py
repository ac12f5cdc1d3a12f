"""The tests' one way to read from a Starlette TestClient WebSocket: with a bound.

`WebSocketTestSession.receive_json()` waits forever, so a server that stops sending hangs the suite.
`receive_json(ws, what)` and `receive_text(ws, what)` wait at most `timeout` seconds and then fail with an
AssertionError naming what they waited for. The read runs on the session's own event loop (its portal)
under `anyio.fail_after`, which cancels the pending receive cleanly, so a later read loses no message;
the caller's wait on that task is bounded too (`timeout` plus a grace), so that even an event loop
blocked by the server cannot hang the test. A close or denial from the server raises as Starlette's
own reads do (`WebSocketDisconnect`).

(The websockets-library clients of the other tests read with `recv(timeout=...)`, which is bounded already.)
"""

from __future__ import annotations

import json
from typing import Any

import anyio
from starlette.testclient import WebSocketTestSession
from starlette.types import Message

DEFAULT_TIMEOUT = 30.0  # seconds: as tests/polling.py's, long enough for a loaded two-core machine
GRACE = 5.0  # seconds more for the event loop itself to answer


def receive(ws: WebSocketTestSession, what: str, timeout: float = DEFAULT_TIMEOUT) -> Message:
    """The next ASGI message the server sent on `ws`, waiting at most `timeout` seconds.

    Raises:
        AssertionError: nothing arrived in time; the message names `what`.
    """

    async def bounded() -> Message:
        with anyio.fail_after(timeout):
            return await ws._send_rx.receive()

    future = ws.portal.start_task_soon(bounded)
    try:
        return future.result(timeout=timeout + GRACE)
    except TimeoutError:  # from fail_after, or from the bounded wait on a blocked loop
        future.cancel()
        raise AssertionError(f"waited {timeout:g} s on the WebSocket for {what}; nothing arrived") from None


def receive_text(ws: WebSocketTestSession, what: str, timeout: float = DEFAULT_TIMEOUT) -> str:
    """The next text frame on `ws` (see `receive`); a close from the server raises `WebSocketDisconnect`."""
    message = receive(ws, what, timeout)
    ws._raise_on_close(message)
    return str(message["text"])


def receive_json(ws: WebSocketTestSession, what: str, timeout: float = DEFAULT_TIMEOUT) -> Any:
    """The next text frame on `ws`, parsed as JSON (see `receive_text`)."""
    return json.loads(receive_text(ws, what, timeout))
