"""`CommandQueue`: work that other threads hand to one owning thread, each answered through a future.

The owner (a run's learner thread) is the only thread that touches its state; every other thread asks
it to act with `call(action)` and waits for the result or the exception. The owner takes commands with
`next` (waiting at most as long as it can spare) or `drain` (all that are waiting), runs each with
`run`, and at the end `close`s the queue: later calls, and those still queued, are refused with
NotFoundError. An action leaves the owner's loop by raising `ShutdownError`, which may carry the error
its caller is answered with.
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Callable
from concurrent.futures import Future
from dataclasses import dataclass
from typing import Any, TypeVar

from horde.runs.errors import BusyError, NotFoundError

T = TypeVar("T")


@dataclass
class Command:
    action: Callable[[], Any]
    future: Future[Any]


class ShutdownError(Exception):
    """Raised by an action to make the owning thread leave its loop; `failure` answers the caller if set."""

    def __init__(self, failure: Exception | None = None) -> None:
        super().__init__()
        self.failure = failure


class CommandQueue:
    """The commands of one owning thread.

    Args:
        owner: how messages name the owner ("run 'ab12'").
    """

    def __init__(self, owner: str) -> None:
        self.owner = owner
        self._queue: queue.SimpleQueue[Command] = queue.SimpleQueue()
        self._gate = threading.Lock()  # guards `_closed` against commands queued after `close`
        self._closed = False

    def call(self, action: Callable[[], T], timeout: float | None) -> T:
        """Run `action` in the owning thread and return its result (or raise its exception).

        Raises:
            NotFoundError: the queue is closed (the owner has been deleted).
            BusyError: the owner did not get to the command within `timeout` seconds.
        """
        future: Future[Any] = Future()
        with self._gate:
            if self._closed:
                raise NotFoundError(f"{self.owner} has been deleted")
            self._queue.put(Command(action, future))
        try:
            result: T = future.result(timeout)
            return result
        except TimeoutError:
            raise BusyError(f"{self.owner} did not answer within {timeout} s") from None

    # ------------------------------------------------------------------------------------------
    # The owning thread

    def next(self, timeout: float | None = None) -> Command | None:
        """The next command, waiting for one at most `timeout` seconds (None: until one comes)."""
        try:
            return self._queue.get(timeout=timeout)
        except queue.Empty:
            return None

    def run(self, command: Command) -> None:
        """Run one command and answer its caller; a ShutdownError is answered, then raised."""
        if not command.future.set_running_or_notify_cancel():
            return
        try:
            result = command.action()
        except ShutdownError as exc:
            if exc.failure is not None:
                command.future.set_exception(exc.failure)
            else:
                command.future.set_result(None)
            raise
        except BaseException as exc:
            command.future.set_exception(exc)
        else:
            command.future.set_result(result)

    def drain(self) -> None:
        """Run every command that is waiting."""
        while True:
            try:
                command = self._queue.get_nowait()
            except queue.Empty:
                return
            self.run(command)

    def close(self) -> None:
        """Refuse every later call and every command still queued (NotFoundError)."""
        with self._gate:
            self._closed = True
        while True:
            try:
                command = self._queue.get_nowait()
            except queue.Empty:
                return
            if command.future.set_running_or_notify_cancel():
                command.future.set_exception(NotFoundError(f"{self.owner} has been deleted"))
