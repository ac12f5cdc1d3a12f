"""`Saver`: one background thread that writes to the store, in the order the writes were handed over.

Learner threads hand their saves to it (the state is frozen in the learner thread, cheaply; encoding
and the SQLite transaction happen here), so a periodic snapshot costs the learner a copy of its
arrays instead of the whole write. A save that must be on disk before the request that caused it is
answered (pause, finish, shutdown) waits for its future; writes of one run stay in order because there
is one thread and one queue.
"""

from __future__ import annotations

import logging
import queue
import threading
from collections.abc import Callable
from concurrent.futures import Future
from typing import Any

log = logging.getLogger(__name__)


class Saver:
    """The writer thread of one run manager. `stop()` writes what is queued, then ends the thread."""

    def __init__(self) -> None:
        self._queue: queue.SimpleQueue[tuple[Callable[[], Any], Future[Any]] | None] = queue.SimpleQueue()
        self._thread = threading.Thread(target=self._loop, name="horde-saver", daemon=True)
        self._thread.start()

    def submit(self, write: Callable[[], Any]) -> Future[Any]:
        """Queue a write; its future holds the write's result (or its exception)."""
        future: Future[Any] = Future()
        if not self._thread.is_alive():  # stopped: write in the caller's thread
            self._run(write, future)
        else:
            self._queue.put((write, future))
        return future

    def _run(self, write: Callable[[], Any], future: Future[Any]) -> None:
        try:
            future.set_result(write())
        except BaseException as exc:
            log.error("a background write failed", exc_info=exc)
            future.set_exception(exc)

    def _loop(self) -> None:
        while (item := self._queue.get()) is not None:
            self._run(*item)

    def stop(self, timeout: float = 60.0) -> None:
        """Finish the queued writes and end the thread."""
        if self._thread.is_alive():
            self._queue.put(None)
            self._thread.join(timeout)
        while True:  # writes handed over while it stopped
            try:
                item = self._queue.get_nowait()
            except queue.Empty:
                return
            if item is not None:
                self._run(*item)
