"""A worker in a thread, over an in-memory channel: how a Ray actor hosts a run's worker.

`QueueChannel` is the worker's `Channel` when the worker is not a process of its own: the host puts the API
process's messages in (`deliver`) and takes the worker's out (`take`, waiting for some). A Ray actor
(`ray_host.RunHost`) runs the worker's loop in a thread of the actor's process over one of these, and its
remote methods are `deliver` and `take`.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Callable
from typing import Any

_CLOSED = object()


class QueueChannel:
    """Messages to the worker (`deliver` -> `poll`/`recv`) and from it (`send` -> `take`)."""

    def __init__(self) -> None:
        self._inbox: deque[Any] = deque()
        self._outbox: deque[Any] = deque()
        self._in = threading.Condition()
        self._out = threading.Condition()
        self.ended = threading.Event()
        self.error = ""  # what the worker's entry raised, if it did

    # The worker's side

    def poll(self, timeout: float | None) -> bool:
        with self._in:
            return self._in.wait_for(lambda: bool(self._inbox), timeout)

    def recv(self) -> Any:
        """The next message, waiting for one (as a connection's `recv` does)."""
        with self._in:
            self._in.wait_for(lambda: bool(self._inbox))
            message = self._inbox.popleft()
        if message is _CLOSED:
            raise EOFError("the channel is closed")
        return message

    def send(self, message: Any) -> None:
        with self._out:
            self._outbox.append(message)
            self._out.notify_all()

    # The host's side

    def deliver(self, message: Any) -> None:
        with self._in:
            self._inbox.append(message)
            self._in.notify_all()

    def close(self) -> None:
        """The API process has gone: the worker's next `recv` raises EOFError."""
        self.deliver(_CLOSED)

    def take(self, wait: float) -> list[Any]:
        """Every message the worker has sent, waiting up to `wait` seconds for one (none once it has ended)."""
        deadline = time.monotonic() + wait
        with self._out:
            while not self._outbox and not self.ended.is_set():
                left = deadline - time.monotonic()
                if left <= 0:
                    break
                self._out.wait(min(left, 0.05))
            taken = list(self._outbox)
            self._outbox.clear()
        return taken


def run_in_thread(entry: Callable[[Any], None], channel: QueueChannel, name: str) -> threading.Thread:
    """Run a worker's entry over `channel` in a daemon thread; the channel says when it has ended."""

    def run() -> None:
        try:
            entry(channel)
        except BaseException as exc:
            channel.error = f"{type(exc).__name__}: {exc}"
            raise
        finally:
            channel.ended.set()
            with channel._out:
                channel._out.notify_all()

    thread = threading.Thread(target=run, name=name, daemon=True)
    thread.start()
    return thread
