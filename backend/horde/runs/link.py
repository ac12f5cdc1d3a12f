"""The API's end of one worker (`WorkerLink`): sending it messages, calling it and waiting for the reply, and
knowing whether it is alive, moving, stalled or gone. The executor (`executor.py`, or Ray's `ray_link.py`) makes
links and feeds them what their workers send; a `Listener` (the run, stream run, job or study the worker works
for) hears the rest.
"""

from __future__ import annotations

import itertools
import signal
import threading
import time
from collections.abc import Callable
from concurrent.futures import Future
from concurrent.futures import TimeoutError as FutureTimeout
from typing import Any, Protocol

from horde.runs import messages as m
from horde.runs.errors import BusyError, RunError

COMMAND_TIMEOUT = 600.0  # a call waits this long at most, however busy (and alive) its worker is
READY_TIMEOUT = 600.0  # building a run (compiling kernels on a cold cache included) may take this long
STALL_SECONDS = 30.0  # a worker whose main loop has not moved for this long is reported (a setting)
TICK = 0.25  # how often a waiting call looks at its worker (and the switchboard at every worker)
END_WAIT = 3.0  # how long a caller that finds its worker gone waits for the end to be told (the exit code: <= 1 s)


class WorkerGoneError(RunError):
    """The worker has ended (crashed, killed, or stopped): nothing can be asked of it."""


def exit_reason(code: int | None) -> str:
    """How a process ended, for a person: its signal's name, or its exit code."""
    if code is None:
        return "its connection closed"
    if code < 0:
        try:
            name = signal.Signals(-code).name
        except ValueError:
            name = "an unknown signal"
        return f"killed by signal {-code} ({name})"
    return f"exited with code {code}"


def stall_words(seconds: float, doing: str, who: str = "its worker") -> str:
    """A stall for a person: how long the worker has not answered and, once its beat says, what holds it (a
    stall reported again when the beat names it reads differently from the first report)."""
    return f"{who} has not answered for {seconds:.0f} s" + (f" (busy with {doing})" if doing else "")


class Listener(Protocol):
    """Who hears a worker: the run, stream run, job or study it works for."""

    def on_message(self, message: m.FromWorker) -> None: ...
    def on_reply(self, command: m.Command | None, reply: m.Reply) -> Any:
        """A reply's effects (its update, its save), before its caller sees it; what it returns goes to the
        caller with the reply (a save's future). `command` is None for a call nobody knows any more."""
        ...

    def on_exit(self, reason: str) -> None: ...
    def on_stall(self, seconds: float, doing: str) -> None: ...


class WorkerLink:
    """The API's end of one worker.

    Args:
        kind: "process" or "ray".
        send: sends one message to the worker (raises OSError when its connection is gone).
        listener: hears the worker's messages, its end and its stalls.
    """

    def __init__(self, kind: str, send: Callable[[Any], None], listener: Listener,
                 stopper: Callable[[WorkerLink], None] | None = None) -> None:  # fmt: skip
        self.kind = kind
        self._send = send
        self._stopper = stopper
        self.listener = listener
        self.pid: int | None = None
        self.node: str | None = None
        self.alive = True
        self.stopping = False  # the API asked it to end: its end is no news
        self.exit_code: int | None = None
        self.connection_closed = False
        self.reason = ""
        self.ready: Future[m.Ready] = Future()
        self.ended = threading.Event()
        self._calls: dict[int, Future[tuple[m.Reply, Any]]] = {}
        self._commands: dict[int, m.Command] = {}  # sent and not yet answered (a caller may have given up)
        self._cids = itertools.count(1)
        self._lock = threading.Lock()
        self._progress: int | None = None
        self._moved_at = time.monotonic()
        self.stalled = False
        self.doing = ""

    # ------------------------------------------------------------------------------------------
    # Sending and calling (any thread)

    def send(self, message: Any) -> None:
        """Send one message.

        Raises:
            WorkerGoneError: the worker has ended.
        """
        if not self.alive:
            raise WorkerGoneError(self.reason or "the worker has ended")
        try:
            self._send(message)
        except (OSError, EOFError, ValueError) as exc:
            raise WorkerGoneError(self.reason or f"its connection failed: {exc}") from None

    def gone(self) -> bool:
        """Whether the worker has ended; if so, once its listener has heard why (a bounded wait: `end` marks the link
        dead before it tells the listener), so that the caller reads the state the end left."""
        if self.alive:
            return False
        self.ended.wait(END_WAIT)
        return True

    def call(self, command: m.Command, timeout: float = COMMAND_TIMEOUT,
             abandoned: Callable[[], bool] | None = None) -> tuple[m.Reply, Any]:  # fmt: skip
        """Send a command and wait for its reply: at most `timeout` seconds, and no longer than the worker keeps
        moving (a stall gives up at once); `abandoned()` turning true sends `Cancel` and keeps waiting for the
        (cancelled) reply.

        Raises:
            WorkerGoneError: the worker ended before it answered (raised once its listener has heard why: a
                connection closes up to a second before the worker's exit code is known, `executor.py`).
            BusyError: no answer within `timeout`, or the worker stopped moving.
        """
        future: Future[tuple[m.Reply, Any]] = Future()
        with self._lock:
            cid = next(self._cids)
            self._calls[cid] = future
            self._commands[cid] = command
        try:
            try:
                self.send(m.Call(cid, command))
            except WorkerGoneError as exc:
                self.ended.wait(END_WAIT)
                raise WorkerGoneError(self.reason or str(exc)) from None
            deadline = time.monotonic() + timeout
            cancelled = False
            while True:
                try:
                    return future.result(min(TICK, max(0.0, deadline - time.monotonic())))
                except FutureTimeout:
                    pass
                if abandoned is not None and not cancelled and abandoned():
                    cancelled = True
                    self.send(m.Cancel(cid))
                if self.stalled:
                    raise BusyError(f"its worker has not answered for {self.stall_seconds():.0f} s"
                                    + (f" (busy with {self.doing})" if self.doing else "")) from None  # fmt: skip
                if time.monotonic() >= deadline:
                    raise BusyError(f"its worker did not answer within {timeout:g} s") from None
        finally:
            with self._lock:
                self._calls.pop(cid, None)

    def stop(self) -> None:
        """End the worker (asked to end already, or not): it is given a moment, then terminated, then killed."""
        self.stopping = True
        if self._stopper is not None:
            self._stopper(self)

    def wait_ready(self, timeout: float = READY_TIMEOUT) -> m.Ready:
        """The worker's Ready (its build's result). A build that keeps the worker's loop still (a Horde of
        thousands of demons compiled on a loaded machine, kernels compiled on a cold cache) is waited for, up to
        `timeout`: its stall is reported meanwhile, not taken for a hang.

        Raises:
            WorkerGoneError: it ended first.
            BusyError: not within `timeout`.
        """
        try:
            return self.ready.result(timeout)
        except FutureTimeout:
            raise BusyError(f"its worker was not ready within {timeout:g} s") from None

    def stall_seconds(self) -> float:
        return time.monotonic() - self._moved_at

    # ------------------------------------------------------------------------------------------
    # From the switchboard's thread

    def deliver(self, message: m.FromWorker) -> None:
        """One message of the worker."""
        self._heard()
        if isinstance(message, m.Reply):
            with self._lock:
                future = self._calls.get(message.cid)
                command = self._commands.pop(message.cid, None)
            token = self.listener.on_reply(command, message)  # its effects count even if nobody waits any more
            if future is not None and not future.done():
                future.set_result((message, token))
            return
        if isinstance(message, m.Beat):
            self._beat(message)
            return
        if isinstance(message, m.Ready):
            self.pid = message.pid or self.pid
            self.node = message.node or self.node
            if not self.ready.done():
                self.ready.set_result(message)
            return
        self.listener.on_message(message)

    def _heard(self) -> None:
        """Any message is a sign of life; a Beat also says whether the main loop moves."""
        if self._progress is None:
            self._moved_at = time.monotonic()

    def _beat(self, beat: m.Beat) -> None:
        if beat.progress != self._progress or beat.doing == m.COMPILING:
            self._progress = beat.progress
            self._moved_at = time.monotonic()
        changed, self.doing = beat.doing != self.doing, beat.doing
        if self.stalled and self.stall_seconds() < TICK * 4:
            self.stalled = False
            self.listener.on_stall(0.0, "")
        elif self.stalled and changed:  # (the stall was reported before the beat that names what holds it)
            self.listener.on_stall(self.stall_seconds(), self.doing)

    def check(self, stall_seconds: float) -> None:
        """Report a worker whose main loop has not moved for `stall_seconds` (once, until it moves again)."""
        if self.alive and not self.stalled and self.stall_seconds() >= stall_seconds:
            self.stalled = True
            self.listener.on_stall(self.stall_seconds(), self.doing)

    def end(self, reason: str) -> None:
        """The worker has ended: fail what waits for it, tell the listener (unless it was asked to end)."""
        with self._lock:
            if not self.alive:
                return
            self.reason = reason  # before `alive`: whoever sees the worker gone can read why
            self.alive = False
            calls, self._calls = list(self._calls.values()), {}
        if not self.stopping:  # first, so that a call that fails below reads the state the end left
            self.listener.on_exit(reason)
        gone = WorkerGoneError(reason)
        for future in calls:
            if not future.done():
                future.set_exception(gone)
        if not self.ready.done():
            self.ready.set_exception(gone)
        self.ended.set()


class Executor(Protocol):
    """What starts workers: processes of this machine (`executor.ProcessExecutor`) or Ray actors
    (`ray_link.RayExecutor`)."""

    kind: str

    def start(self) -> None: ...
    def spawn(self, entry: Callable[[Any], None], init: Any, listener: Listener) -> WorkerLink: ...
    def stop(self) -> None: ...
