"""WebSocket streams of run states: at most `rate` messages per second per client, never waiting on one.

One broadcaster task wakes `rate` times a second while anyone streams; for every streamed run whose
view has changed it builds one JSON message (a `StateOut` carrying the events since that run's last
message) and offers it to every client's bounded queue. A client whose queue is full (it is `backlog`
messages behind) or whose send does not finish within `send_timeout` is dropped. Learner threads never
see any of this: they only publish views, so learning never waits for a client.
"""

from __future__ import annotations

import asyncio
import contextlib
from dataclasses import dataclass, field

from fastapi import WebSocket
from starlette.websockets import WebSocketState

from horde.runs.errors import NotFoundError
from horde.runs.events import RECENT_EVENTS
from horde.runs.live_run import LiveRun
from horde.runs.manager import RunManager
from horde.server.convert import state_out
from horde.server.stream_protocol import StreamClose, close_reason

# The close codes, from the one source the dashboard's are generated from (stream_protocol.py).
CLOSE_UNKNOWN_RUN = StreamClose.NOT_FOUND
CLOSE_RUN_DELETED = StreamClose.RUN_DELETED
CLOSE_TOO_SLOW = StreamClose.TOO_SLOW
CLOSE_GOING_AWAY = StreamClose.GOING_AWAY
INITIAL_EVENTS = MAX_EVENTS_PER_MESSAGE = RECENT_EVENTS  # the first message's events, and any later one's
# Demons per message at most: a Horde of thousands would make every message megabytes. Each message
# carries the next ones in turn, so every demon is refreshed every `demons / MAX_STREAM_DEMONS` messages.
MAX_STREAM_DEMONS = 200


def demon_window(offset: int, total: int, size: int = MAX_STREAM_DEMONS) -> tuple[list[int], int]:
    """The demon indices of the next message, from `offset` on (wrapping), and the offset after them."""
    if total <= size:
        return list(range(total)), 0
    start = offset % total
    return [(start + k) % total for k in range(size)], (start + size) % total


@dataclass(eq=False)
class _Client:
    queue: asyncio.Queue[str | None]
    close_code: int = CLOSE_GOING_AWAY
    close_reason: str = ""


@dataclass(eq=False)
class _Channel:
    run: LiveRun
    last_seq: int
    last_event: int
    clients: set[_Client] = field(default_factory=set)
    demon_offset: int = 0


class StreamHub:
    """The streams of one server.

    Args:
        manager: where runs are looked up.
        rate: messages per second per client at most.
        backlog: messages a client may fall behind before it is dropped.
        send_timeout: seconds one send may take before its client is dropped.
    """

    def __init__(self, manager: RunManager, rate: float = 30.0, backlog: int = 64, send_timeout: float = 5.0) -> None:
        self.manager = manager
        self.rate = rate
        self.backlog = backlog
        self.send_timeout = send_timeout
        self._channels: dict[str, _Channel] = {}
        self._ticker: asyncio.Task[None] | None = None

    @property
    def clients(self) -> int:
        return sum(len(c.clients) for c in self._channels.values())

    async def serve(self, websocket: WebSocket, run_id: str) -> None:
        """Stream run `run_id` to one client (its socket accepted) until it leaves, falls behind, or the run
        is deleted."""
        try:
            run = self.manager.get(run_id)
        except NotFoundError as exc:
            await websocket.close(code=CLOSE_UNKNOWN_RUN, reason=close_reason(str(exc)))
            return
        client = _Client(asyncio.Queue(maxsize=self.backlog))
        channel = self._join(run, client)
        events = [e for e in run.events.recent(INITIAL_EVENTS) if e.seq <= channel.last_event]
        view = run.view
        first, _ = demon_window(0, view.num_demons)
        client.queue.put_nowait(state_out(view, events, first).model_dump_json())
        sender = asyncio.create_task(self._send(websocket, channel, client), name=f"stream-client-{run.id}")
        try:
            await self._receive(websocket)
        finally:
            sender.cancel()
            self._leave(channel, client)

    async def close(self) -> None:
        """Stop every broadcaster and tell every client that the server is going away."""
        for channel in list(self._channels.values()):
            for client in list(channel.clients):
                self._drop(client, CLOSE_GOING_AWAY, "the server is stopping")
        self._channels.clear()
        if self._ticker is not None:
            self._ticker.cancel()

    # ------------------------------------------------------------------------------------------

    def _join(self, run: LiveRun, client: _Client) -> _Channel:
        channel = self._channels.get(run.id)
        if channel is None or channel.run is not run:
            channel = _Channel(run, run.view.seq, run.events.last_seq)
            self._channels[run.id] = channel
        channel.clients.add(client)
        if self._ticker is None or self._ticker.done():
            self._ticker = asyncio.create_task(self._broadcast(), name="stream-broadcaster")
        return channel

    def _leave(self, channel: _Channel, client: _Client) -> None:
        channel.clients.discard(client)
        if not channel.clients and self._channels.get(channel.run.id) is channel:
            del self._channels[channel.run.id]

    async def _broadcast(self) -> None:
        while self._channels:
            await asyncio.sleep(1.0 / self.rate)
            for channel in list(self._channels.values()):
                self._tick(channel)

    def _tick(self, channel: _Channel) -> None:
        """Offer the run's new state to its clients, if it has changed; close them if the run is gone."""
        run = channel.run
        view = run.view
        if view.seq == channel.last_seq:
            if not run.is_alive():
                for client in list(channel.clients):
                    self._drop(client, CLOSE_RUN_DELETED, f"run {run.id!r} was deleted")
            return
        events = run.events.since(channel.last_event, MAX_EVENTS_PER_MESSAGE)
        channel.last_seq = view.seq
        if events:
            channel.last_event = events[-1].seq
        demons, channel.demon_offset = demon_window(channel.demon_offset, view.num_demons)
        message = state_out(view, events, demons).model_dump_json()
        for client in list(channel.clients):
            try:
                client.queue.put_nowait(message)
            except asyncio.QueueFull:
                self._drop(client, CLOSE_TOO_SLOW, f"the client fell {self.backlog} messages behind")

    def _drop(self, client: _Client, code: int, reason: str) -> None:
        """Empty the client's queue and leave only the instruction to close."""
        client.close_code, client.close_reason = code, reason
        while not client.queue.empty():
            client.queue.get_nowait()
        client.queue.put_nowait(None)

    async def _send(self, websocket: WebSocket, channel: _Channel, client: _Client) -> None:
        """Send the client's messages until it is dropped or a send fails; then close its socket."""
        try:
            while True:
                message = await client.queue.get()
                if message is None:
                    break
                async with asyncio.timeout(self.send_timeout):  # no task a send, as wait_for makes on 3.11
                    await websocket.send_text(message)
        except asyncio.CancelledError:
            raise
        except Exception:  # a send that timed out, or a broken connection
            client.close_code, client.close_reason = CLOSE_TOO_SLOW, "a send timed out or failed"
        self._leave(channel, client)
        if websocket.application_state == WebSocketState.CONNECTED:
            with contextlib.suppress(Exception):
                await asyncio.wait_for(websocket.close(client.close_code, client.close_reason), self.send_timeout)

    async def _receive(self, websocket: WebSocket) -> None:
        """Read (and ignore) what the client sends, until it disconnects."""
        with contextlib.suppress(RuntimeError):  # receive() after a disconnect
            while True:
                message = await websocket.receive()
                if message["type"] == "websocket.disconnect":
                    return
