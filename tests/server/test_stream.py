"""WS /api/runs/{id}/stream: state messages, at most ~30 a second, and slow or dead clients dropped."""

from __future__ import annotations

import asyncio
import time
from collections.abc import Callable
from typing import Any

import pytest
from fastapi.testclient import TestClient
from starlette.websockets import WebSocketDisconnect, WebSocketState

from horde.runs.manager import RunManager
from horde.server.stream import CLOSE_RUN_DELETED, CLOSE_TOO_SLOW, CLOSE_UNKNOWN_RUN, StreamHub
from horde.spec import RunSpec
from polling import wait_until
from sockets import receive_json

from .helpers import make_spec


def test_messages_carry_the_state_and_new_events(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run()
    with client.websocket_connect(f"/api/runs/{run_id}/stream") as ws:
        first = receive_json(ws, "the first state")
        assert first["type"] == "state" and first["run"] == run_id and first["step"] == 0
        client.post(f"/api/runs/{run_id}/step", json={"steps": 300})
        message = receive_json(ws, "the state after 300 steps")
        assert message["step"] == 300 and set(message["predictions"]) == {"base", "steps"}
        assert "episode" in {e["kind"] for e in message["events"]}


def test_at_most_about_30_messages_a_second(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run(make_spec(), start="true")
    began = time.monotonic()  # before the connection: messages queued for a slow reader count too
    with client.websocket_connect(f"/api/runs/{run_id}/stream") as ws:
        steps = [receive_json(ws, "the next state")["step"] for _ in range(17)]
        elapsed = time.monotonic() - began
    client.post(f"/api/runs/{run_id}/pause")
    # the hub sends at most 30 a second: 17 messages take at least 16 periods (one of slack here)
    assert elapsed >= 15 / 30, f"17 messages in {elapsed:.3f} s: more than 30 a second"
    assert steps == sorted(steps) and steps[-1] > steps[0]


def test_unknown_run_closes_with_4404(client: TestClient) -> None:
    with (
        client.websocket_connect("/api/runs/nope/stream") as ws,
        pytest.raises(WebSocketDisconnect) as closed,
    ):
        receive_json(ws, "the unknown-run close")
    assert closed.value.code == CLOSE_UNKNOWN_RUN


def test_deleting_the_run_closes_its_streams(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run(make_spec(), start="true")
    with client.websocket_connect(f"/api/runs/{run_id}/stream") as ws:
        receive_json(ws, "the first state")
        assert client.delete(f"/api/runs/{run_id}").status_code == 204
        with pytest.raises(WebSocketDisconnect) as closed:
            for _ in range(200):
                receive_json(ws, "the run-deleted close")
    assert closed.value.code == CLOSE_RUN_DELETED


class FakeSocket:
    """An accepted client (the route accepts it) that takes `send_delay` seconds per message (forever when
    None after the first)."""

    def __init__(self, send_delay: float | None) -> None:
        self.send_delay = send_delay
        self.sent = 0
        self.closed: tuple[int, str] | None = None
        self.application_state = WebSocketState.CONNECTED
        self.client_state = WebSocketState.CONNECTED
        self._gone = asyncio.Event()

    async def send_text(self, text: str) -> None:
        self.sent += 1
        if self.sent > 1:
            await asyncio.sleep(self.send_delay if self.send_delay is not None else 3600)

    async def receive(self) -> dict[str, Any]:
        await self._gone.wait()
        return {"type": "websocket.disconnect", "code": 1000}

    async def close(self, code: int = 1000, reason: str = "") -> None:
        self.closed = (code, reason)
        self.application_state = WebSocketState.DISCONNECTED
        self._gone.set()  # a polite client answers the close


@pytest.mark.parametrize(("send_delay", "reason"), [(None, "timed out"), (0.2, "behind")])
def test_slow_or_stuck_clients_are_dropped_and_learning_goes_on(send_delay: float | None, reason: str) -> None:
    manager = RunManager()
    view = manager.create(RunSpec.model_validate(make_spec()), start=True)
    run = manager.get(view.id)
    hub = StreamHub(manager, rate=100.0, backlog=4, send_timeout=0.5)
    socket = FakeSocket(send_delay)

    async def stream() -> None:
        await asyncio.wait_for(hub.serve(socket, view.id), timeout=10)  # type: ignore[arg-type]

    try:
        asyncio.run(stream())
        assert socket.closed is not None and socket.closed[0] == CLOSE_TOO_SLOW and reason in socket.closed[1]
        assert hub.clients == 0
        dropped = run.view.total_steps
        wait_until(lambda: run.view.total_steps > dropped, "learning after the client was dropped")
        assert run.view.status == "running"
    finally:
        manager.stop()


def test_a_run_at_full_speed_sends_only_its_latest_events(client: TestClient, create_run: Callable[..., str]) -> None:
    """Hundreds of episodes end between two messages at full speed; each message keeps the latest few."""
    from horde.server.stream import MAX_EVENTS_PER_MESSAGE

    run_id = create_run(start="true")
    with client.websocket_connect(f"/api/runs/{run_id}/stream") as ws:
        sizes = []
        for _ in range(5):
            message = receive_json(ws, "the next state at full speed")
            sizes.append(len(message["events"]))
            seqs = [e["seq"] for e in message["events"]]
            assert seqs == sorted(seqs), "events come oldest first"
    assert max(sizes) <= MAX_EVENTS_PER_MESSAGE


def test_a_large_hordes_messages_stay_bounded_and_take_turns(client: TestClient) -> None:
    from horde.server.stream import MAX_STREAM_DEMONS

    count = 2 * MAX_STREAM_DEMONS + 50
    demons = [{"name": f"d{i}", "policy": "uniform", "cumulant": 1, "learner": "td"} for i in range(count)]
    run_id = client.post("/api/runs", json=make_spec(demons=demons, behaviour="uniform")).json()["id"]
    seen: set[str] = set()
    with client.websocket_connect(f"/api/runs/{run_id}/stream") as ws:
        for steps in range(1, 5):
            message = receive_json(ws, "the next state of the large Horde")
            assert message["demon_total"] == count
            assert len(message["predictions"]) == len(message["metrics"]) == MAX_STREAM_DEMONS
            assert set(message["predictions"]) == set(message["metrics"])
            seen |= set(message["predictions"])
            client.post(f"/api/runs/{run_id}/step", json={"steps": steps})
    assert len(seen) == count, "three messages in turn carry every demon"
