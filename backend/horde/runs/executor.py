"""The run executor, API side: starting workers, talking to them, and watching them.

Every live run, protocol job, stream run and study driver has a worker (`WorkerLink` here, its end of the
connection). Workers are processes of this machine, forked by the fork server (`forkserver.py`), or Ray
actors on a cluster (`ray_link.py`, through a bridge process that is the cluster's driver): the links are the
same to everyone else. One thread, the switchboard, reads every worker's connection and the fork server's:

- a `Reply` resolves the call waiting for it; `Ready` the spawn waiting for it; a `Beat` says the worker is
  alive (and whether its main loop moves); everything else goes to the link's listener (the run, job, ...);
- a connection that closes, or an exit the fork server reports, is the worker's end: its calls fail with
  `WorkerGoneError` and its listener hears why (`exit_reason`: the signal or exit code);
- a worker whose main loop has not moved for `stall_seconds` is reported to its listener (`on_stall`), and
  calls waiting on it give up with BusyError instead of waiting on.

Nothing here waits on a worker without a bound.
"""

from __future__ import annotations

import contextlib
import logging
import os
import signal
import socket
import threading
import time
from collections.abc import Callable
from multiprocessing.connection import Connection, wait
from typing import Any, Protocol

from horde.runs import forkserver
from horde.runs import messages as m
from horde.runs.forkserver import ForkServer
from horde.runs.link import STALL_SECONDS, TICK, Listener, WorkerLink, exit_reason

log = logging.getLogger(__name__)

STOP_GRACE = 5.0  # a worker asked to end gets this long before it is terminated, then killed


class Port(Protocol):
    """A connection the switchboard reads: one worker's (a process), or a bridge's carrying several (Ray)."""

    connection: Connection

    def dispatch(self, message: Any) -> None: ...
    def closed(self) -> None: ...


class ProcessPort:
    """A worker process's connection; `on_close` hears its end."""

    def __init__(self, connection: Connection, link: WorkerLink, on_close: Callable[[], None]) -> None:
        self.connection = connection
        self.link = link
        self.closed = on_close

    def dispatch(self, message: Any) -> None:
        self.link.deliver(message)


class Switchboard:
    """The thread that reads every worker's connection and watches their progress."""

    def __init__(self, stall_seconds: float = STALL_SECONDS) -> None:
        self.stall_seconds = stall_seconds
        self._ports: dict[int, Port] = {}  # by the connection's fileno
        self._others: dict[Any, Callable[[], None]] = {}  # other readable objects and what reads them
        self._links: list[WorkerLink] = []
        self._lock = threading.Lock()
        self._wake_r, self._wake_w = socket.socketpair()
        self._stop = False
        self._thread = threading.Thread(target=self._run, name="horde-switchboard", daemon=True)
        self._thread.start()

    def add(self, port: Port) -> None:
        with self._lock:
            self._ports[port.connection.fileno()] = port
        self._wake()

    def watch(self, link: WorkerLink) -> None:
        with self._lock:
            self._links.append(link)

    def add_reader(self, readable: Any, read: Callable[[], None]) -> None:
        with self._lock:
            self._others[readable] = read
        self._wake()

    def remove_reader(self, readable: Any) -> None:
        with self._lock:
            self._others.pop(readable, None)
        self._wake()

    def _wake(self) -> None:
        with contextlib.suppress(OSError):
            self._wake_w.send(b"x")

    def stop(self) -> None:
        self._stop = True
        self._wake()
        self._thread.join(10)

    def _run(self) -> None:
        while not self._stop:
            with self._lock:
                ports = list(self._ports.values())
                others = dict(self._others)
            try:
                ready = wait([self._wake_r, *(p.connection for p in ports), *others], TICK)
            except OSError:  # a connection closed under us: look again
                ready = []
            for item in ready:
                if item is self._wake_r:
                    with contextlib.suppress(OSError):
                        self._wake_r.recv(4096)
                elif item in others:
                    self._guarded(others[item])
                else:
                    self._read(next(p for p in ports if p.connection is item))
            self._check()

    def _guarded(self, action: Callable[[], None]) -> None:
        try:
            action()
        except Exception:  # the switchboard never dies of one message
            log.exception("the switchboard could not handle a message")

    def _read(self, port: Port) -> None:
        """Every message waiting on the port; at its end, the port is dropped and told."""
        try:
            while port.connection.poll(0):
                message = port.connection.recv()
                self._guarded(lambda: port.dispatch(message))  # noqa: B023 (called at once)
        except (EOFError, OSError):
            with self._lock:
                self._ports = {k: p for k, p in self._ports.items() if p is not port}
            with contextlib.suppress(OSError):
                port.connection.close()
            self._guarded(port.closed)

    def _check(self) -> None:
        with self._lock:
            self._links = [link for link in self._links if link.alive]
            links = list(self._links)
        for link in links:
            self._guarded(lambda link=link: link.check(self.stall_seconds))  # type: ignore[misc]


class ProcessExecutor:
    """Workers as processes of this machine, forked by the fork server.

    Args:
        stall_seconds: a worker whose main loop has not moved for this long is reported.
    """

    kind = "process"

    def __init__(self, stall_seconds: float = STALL_SECONDS) -> None:
        self.stall_seconds = stall_seconds
        self._switchboard: Switchboard | None = None
        self.forkserver: ForkServer | None = None
        self._by_pid: dict[int, WorkerLink] = {}
        self._codes: dict[int, int] = {}  # exit codes heard before the connection's end
        self._lock = threading.Lock()
        self._started = False

    @property
    def switchboard(self) -> Switchboard:
        self.start()
        assert self._switchboard is not None
        return self._switchboard

    def start(self) -> None:
        """Start the switchboard and the fork server (which warms up meanwhile: the first spawn waits for it)."""
        with self._lock:
            if self._started:
                return
            self._started = True
            self._switchboard = Switchboard(self.stall_seconds)
            self.forkserver = forkserver.shared()

    def spawn(self, entry: Callable[[Any], None], init: m.WorkerInit, listener: Listener) -> WorkerLink:
        """A worker running `entry`, sent `init`; its Ready is awaited with `link.wait_ready()`."""
        self.start()
        assert self.forkserver is not None
        pid, connection = self.forkserver.fork(entry, self._exited)
        lock = threading.Lock()

        def send(message: Any) -> None:
            with lock:
                connection.send(message)

        link = WorkerLink("process", send, listener, self.stop_worker)
        link.pid = pid
        port = ProcessPort(connection, link, lambda: self._connection_closed(link))
        with self._lock:
            self._by_pid[pid] = link
            code = self._codes.pop(pid, None)
        link.exit_code = code
        self.switchboard.add(port)
        self.switchboard.watch(link)
        link.send(init)
        return link

    def _exited(self, pid: int, code: int) -> None:
        """The fork server reaped a child."""
        with self._lock:
            link = self._by_pid.pop(pid, None)
            if link is None:
                self._codes[pid] = code
                return
        link.exit_code = code
        if link.connection_closed:
            link.end(exit_reason(code))

    def _connection_closed(self, link: WorkerLink) -> None:
        """A worker's connection closed: it ends once its exit code is known (at most a second later)."""
        link.connection_closed = True
        if link.exit_code is not None:
            link.end(exit_reason(link.exit_code))
            return

        def later() -> None:
            deadline = time.monotonic() + 1.0
            while link.exit_code is None and time.monotonic() < deadline:
                time.sleep(0.02)
            link.end(exit_reason(link.exit_code))

        threading.Thread(target=later, name="horde-exit-reason", daemon=True).start()

    def stop_worker(self, link: WorkerLink, grace: float = STOP_GRACE) -> None:
        """End a worker: wait `grace` seconds for it to end by itself (asked already), then terminate, then kill."""
        link.stopping = True
        if link.ended.wait(grace) or link.pid is None:
            return
        for sig in (signal.SIGTERM, signal.SIGKILL):
            if link.exit_code is not None:
                break
            with contextlib.suppress(ProcessLookupError):
                os.kill(link.pid, sig)
            if link.ended.wait(grace):
                return
        link.end("stopped")

    def stop(self) -> None:
        """Stop the switchboard (the workers were ended by their owners; the fork server serves the process)."""
        with self._lock:
            switchboard, self._switchboard, self._started = self._switchboard, None, False
        if switchboard is not None:
            switchboard.stop()
