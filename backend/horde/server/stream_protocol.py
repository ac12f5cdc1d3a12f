"""The wire format of the WebSocket streams, written once for the server and the dashboard.

As viser generates its client's `WebsocketMessages.ts` from `_messages.py`, the dashboard's stream types
and constants come from here: `add_stream_schemas` puts the streams' messages and close codes into the
OpenAPI schema (components `RunStreamMessage`, `StudyStreamMessage` and `StreamClose`), from which `make
api-types` generates `frontend/src/api/schema.d.ts` (the types) and `frontend/src/api/stream-protocol.ts`
(the close codes as values); `make test` fails when either is out of date. The messages themselves are
the pydantic models `StateOut` (a run's stream, `type: "state"`) and `StudyOut` (a study's stream).
"""

from __future__ import annotations

from enum import IntEnum
from typing import Any

from fastapi import FastAPI


class StreamClose(IntEnum):
    """How the server closes a stream (the WebSocket close code). 1xxx are the protocol's own codes."""

    NORMAL = 1000
    GOING_AWAY = 1001
    ORIGIN_REFUSED = 1008
    TOO_SLOW = 1013
    UNAUTHORIZED = 4401
    FORBIDDEN = 4403
    NOT_FOUND = 4404
    RUN_DELETED = 4410


CLOSE_MEANINGS: dict[StreamClose, str] = {
    StreamClose.NORMAL: "the stream is over (a study stopped)",
    StreamClose.GOING_AWAY: "the server is stopping",
    StreamClose.ORIGIN_REFUSED: "a page of another site may not open the stream",
    StreamClose.TOO_SLOW: "the client fell too far behind, or a send timed out ('try again later')",
    StreamClose.UNAUTHORIZED: "the server requires a token (pushing records to a stream run), or the token given is "
    "not the server's or was revoked",
    StreamClose.FORBIDDEN: "the token's role may not do this (a viewer's, or a student's on another's stream run)",
    StreamClose.NOT_FOUND: "no such run (or study, or stream run)",
    StreamClose.RUN_DELETED: "the run (or stream run) was deleted while streamed",
}

MAX_REASON_BYTES = 123  # RFC 6455: a close frame's reason, in UTF-8


def close_reason(text: str) -> str:
    """`text` cut to what a close frame may carry (a reason may quote an id of any length)."""
    data = text.encode()
    if len(data) <= MAX_REASON_BYTES:
        return text
    return data[: MAX_REASON_BYTES - 3].decode(errors="ignore") + "…"


# Each stream's message: (component, the model it is, what it says).
STREAM_MESSAGES: dict[str, tuple[str, str]] = {
    "RunStreamMessage": (
        "StateOut",
        "A message of WS /api/runs/{id}/stream: the run's state, with the events since the previous message "
        "(at most about 30 a second).",
    ),
    "StudyStreamMessage": (
        "StudyOut",
        "A message of WS /api/studies/{id}/stream: the study, twice a second while it runs, and once when it stops.",
    ),
}


def stream_schemas() -> dict[str, dict[str, Any]]:
    """The OpenAPI components of the streams: the close codes (named in `x-enum-varnames`) and the messages."""
    codes = list(StreamClose)
    schemas: dict[str, dict[str, Any]] = {
        "StreamClose": {
            "title": "StreamClose",
            "type": "integer",
            "enum": [int(code) for code in codes],
            "x-enum-varnames": [code.name for code in codes],
            "x-enum-descriptions": [CLOSE_MEANINGS[code] for code in codes],
            "description": "How the server closes a WebSocket stream: "
            + "; ".join(f"{int(code)} {code.name}: {CLOSE_MEANINGS[code]}" for code in codes),
        }
    }
    for name, (model, description) in STREAM_MESSAGES.items():
        schemas[name] = {"$ref": f"#/components/schemas/{model}", "description": description}
    return schemas


def add_stream_schemas(app: FastAPI) -> None:
    """Add `stream_schemas()` to the app's OpenAPI schema (its `/openapi.json` and the generated types)."""
    build = app.openapi

    def openapi() -> dict[str, Any]:
        if app.openapi_schema is not None:
            return app.openapi_schema
        schema = build()
        found = schema.setdefault("components", {}).setdefault("schemas", {})
        for name, (model, _) in STREAM_MESSAGES.items():
            if model not in found:
                raise RuntimeError(f"the stream message {name} refers to {model}, which no route documents")
        found.update(stream_schemas())
        return schema

    app.openapi = openapi  # type: ignore[method-assign]
