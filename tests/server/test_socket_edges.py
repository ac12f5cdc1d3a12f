"""The WebSocket routes on a real server: every documented close code reaches the client as a close frame
(accepted first, not an HTTP 403 at the handshake), the study stream refuses other sites as the others do,
and the records stream answers a binary frame or a 100,000-deep array with an error and stays open."""

from __future__ import annotations

import json
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import websockets.sync.client as ws_client
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import ClientConnection

from horde.server import Settings
from horde.server.stream_protocol import StreamClose
from serving import RunningServer, health_is_quick, serve_in_thread

from .test_stream_history import records, spec

pytestmark = pytest.mark.serial  # /api/health within 100 ms after each bad socket: a bound on time, so alone

TOKEN = "s3cret"
AUTH = {"Authorization": f"Bearer {TOKEN}"}
EVIL = {"Origin": "http://evil.example"}
STUDY = {
    "scenario": "classroom-offpolicy",
    "runs": 1,
    "measure": {"episodes": 2, "checkpoints": 1},
    "axes": [{"path": "learning.alpha", "values": [0.03]}],
}


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[RunningServer]:
    data: Path = tmp_path_factory.mktemp("sockets") / "data"
    settings = Settings(data=data, token=TOKEN, snapshot_every=3600.0, study_executor="local")
    with serve_in_thread(settings) as running:
        yield running


def connect(server: RunningServer, path: str, headers: dict[str, str] | None = None) -> ClientConnection:
    url = server.url.replace("http://", "ws://") + path
    return ws_client.connect(url, additional_headers=headers, open_timeout=10, close_timeout=5)


def close_of(server: RunningServer, path: str, headers: dict[str, str] | None = None) -> tuple[int, str]:
    """The code and reason the server closes `path` with, before sending anything."""
    with connect(server, path, headers) as ws, pytest.raises(ConnectionClosed) as closed:
        ws.recv(timeout=10)
    assert closed.value.rcvd is not None, "closed without a close frame"
    return closed.value.rcvd.code, closed.value.rcvd.reason


def new_stream(server: RunningServer) -> str:
    created = server.client.post("/api/streams", json=spec(), headers=AUTH)
    assert created.status_code == 201, created.text
    return str(created.json()["id"])


def finished_study(server: RunningServer) -> dict[str, Any]:
    started = server.client.post("/api/studies", json=STUDY, headers=AUTH)
    assert started.status_code == 202, started.text
    deadline = time.monotonic() + 120
    while (study := server.client.get(f"/api/studies/{started.json()['id']}").json())["status"] == "running":
        assert time.monotonic() < deadline, "the study did not finish in 120 s"
        time.sleep(0.2)
    return dict(study)


def test_every_documented_close_code_reaches_the_client(server: RunningServer) -> None:
    stream = new_stream(server)
    expected = {
        "/api/runs/nope/stream": (StreamClose.NOT_FOUND, "nope"),
        "/api/studies/nope/stream": (StreamClose.NOT_FOUND, "nope"),
        "/api/streams/nope/records?token=s3cret": (StreamClose.NOT_FOUND, "nope"),
        f"/api/streams/{stream}/records": (StreamClose.UNAUTHORIZED, "HORDE_TOKEN"),
    }
    for path, (code, reason) in expected.items():
        got_code, got_reason = close_of(server, path)
        assert got_code == code and reason in got_reason, (path, got_code, got_reason)
        health_is_quick(server)
    long_id = "x" * 500  # the reason quotes it: cut to the 123 bytes a close frame carries
    code, reason = close_of(server, f"/api/runs/{long_id}/stream")
    assert code == StreamClose.NOT_FOUND and len(reason.encode()) <= 123


@pytest.mark.parametrize("route", ["runs/{id}/stream", "studies/{id}/stream", "streams/{id}/records"])
def test_a_page_of_another_site_is_refused_with_1008(server: RunningServer, route: str) -> None:
    existing = {"runs": "", "studies": "", "streams": ""}
    kind = route.split("/")[0]
    if kind == "studies":
        existing[kind] = finished_study(server)["id"]
    elif kind == "streams":
        existing[kind] = new_stream(server)
    else:
        existing[kind] = server.client.post("/api/runs", json={"scenario": "experiment1"}, headers=AUTH).json()["id"]
    path = "/api/" + route.format(id=existing[kind]) + ("?token=s3cret" if kind == "streams" else "")
    with connect(server, path) as ws:  # the server's own page (no Origin): served
        assert json.loads(ws.recv(timeout=10))
    assert close_of(server, path, EVIL)[0] == StreamClose.ORIGIN_REFUSED, "nothing is sent to another site"
    health_is_quick(server)


def test_binary_and_deep_messages_get_an_error_and_the_stream_goes_on(server: RunningServer) -> None:
    stream = new_stream(server)
    with connect(server, f"/api/streams/{stream}/records", AUTH) as ws:
        assert json.loads(ws.recv(timeout=10))["type"] == "hello"
        for bad, problem in ((b"\x00\x01binary", "binary"), ("[" * 100_000 + "]" * 100_000, "deep"),
                             ("[" * 60 + "]" * 60, "deep")):  # fmt: skip
            ws.send(bad)
            answer = json.loads(ws.recv(timeout=10))
            assert answer["type"] == "error" and answer["field"] == "message" and problem in answer["message"], answer
            health_is_quick(server)
        ws.send(json.dumps({"records": records(3)}))  # the connection is still open and learning
        learned = json.loads(ws.recv(timeout=30))
        assert learned["type"] == "learned" and learned["learned"] == 3, learned
