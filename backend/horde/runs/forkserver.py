"""A fork server: one process that has the engine and its compiled kernels loaded, and forks every worker.

Starting a worker as a fresh interpreter costs seconds (importing numpy, numba and the engine, loading the
kernels from numba's cache); forked from a process that has done it, it costs milliseconds. The API process
itself is never forked (it has threads; a fork would copy their locks in whatever state they were in): it
starts this server once (`subprocess`, a fresh interpreter in a session of its own, so that a Ctrl-C at the
terminal reaches the API process, which shuts the workers down in order, and not the workers themselves),
which imports the workers' modules and warms the kernels up on small runs, single-threaded, and from then on
forks on request. The server has no threads, so its children start clean.

The control channel is a SOCK_SEQPACKET socket pair (each message whole):

    API -> server   ("fork", entry, fd)       fork; the child runs entry(ProcessChannel(fd)) (fd passed along)
                    EOF                       the API process has gone: the children are killed, the server ends
    server -> API   ("ready", pid, seconds)   preloaded and warmed up in `seconds`
                    ("forked", pid)           one per fork request, in order
                    ("exited", pid, code)     a child ended: its exit code, or minus the signal that killed it

The server reaps every child (no zombies) and reports how each ended; the API process reaps the server. One
server serves the whole API process (`shared()`): the apps a test suite makes one after the other share it.

Why each worker in a session of its own, niced (`_lower_priority`): where the kernel shares the CPU among
sessions first (Linux's autogroups), a worker in the API's session competes with the API inside its group, and
workers sharing one session of their own get one session's share however many learn. In a session of its own
whose group is niced as the process is, each worker competes as a niced process, as without autogroups: it
yields to the API and to the machine's other work, and N runs take N niced shares. Measured with 8 runs, 20
streams, 20 pollers and a 9,000-demon build, on a machine crowded by other sessions (`benchmarks.bench_load`):
`/api/health` p99 24 ms and pollers 10.2 answers a second (load 11 to 14) with these sessions; p99 187 and
431 ms and 1.3 to 2.1 answers a second (load 20 to 26) with the workers in the API's session; 54 and 85 ms
and 9.7 answers a second (load 18 to 24) with all workers in one session of their own, where 8 runs together
also learned no faster than one alone (0.70 times, load 9 to 11; 1.6 times with these sessions at load 3).
"""

from __future__ import annotations

import atexit
import contextlib
import logging
import os
import pickle
import selectors
import signal
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from concurrent.futures import Future
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any

log = logging.getLogger(__name__)

MAX_MESSAGE = 65536
WORKER_NICENESS = 10  # workers yield the CPU to the API process whenever it has requests or streams to serve
PRELOAD = ("horde.runs.worker", "horde.runs.job_workers", "horde.runs.warm")


class ProcessChannel:
    """A worker's end of its connection to the API process, over a socket (`worker.Channel`)."""

    def __init__(self, connection: Connection) -> None:
        self.connection = connection
        self._lock = threading.Lock()

    def poll(self, timeout: float | None) -> bool:
        return self.connection.poll(timeout)

    def recv(self) -> Any:
        return self.connection.recv()

    def send(self, message: Any) -> None:
        with self._lock:
            self.connection.send(message)


# ----------------------------------------------------------------------------------------------
# The API side


class ForkServer:
    """The API process's handle on its fork server: one per process (`shared()`), started on first use and ended
    when the process exits. A thread of its own reads the server's messages."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._process: subprocess.Popen[bytes] | None = None
        self._socket: socket.socket | None = None
        self._ready: Future[float] = Future()
        self._forks: list[Future[int]] = []  # fork requests waiting for their pid, in order
        self._on_exit: dict[int, Callable[[int, int], None]] = {}  # pid -> told how its child ended
        self._exits: dict[int, int] = {}  # exit codes of children nobody listened for yet
        self._stopping = False  # stopped by its process: the children it kills on the way out are no news

    @property
    def pid(self) -> int | None:
        return self._process.pid if self._process is not None else None

    def start(self) -> None:
        """Start the server (returns at once; `fork` waits until it is ready)."""
        with self._lock:
            if self._process is not None:
                return
            ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
            command = f"from horde.runs.forkserver import main; main({theirs.fileno()})"
            env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
            self._process = subprocess.Popen([sys.executable, "-c", command], pass_fds=[theirs.fileno()],
                                             stdin=subprocess.DEVNULL, start_new_session=True, env=env)  # fmt: skip
            theirs.close()
            self._socket = ours
            threading.Thread(target=self._read, args=(ours,), name="horde-forkserver", daemon=True).start()

    def ready(self, timeout: float) -> float:
        """Wait until the server has preloaded and warmed up; its warm-up seconds."""
        return self._ready.result(timeout)

    def fork(self, entry: Callable[[Any], None], on_exit: Callable[[int, int], None],
             timeout: float = 300.0) -> tuple[int, Connection]:  # fmt: skip
        """A new worker running `entry(channel)`: its pid and the API's end of its connection; `on_exit(pid, code)`
        hears how it ended.

        Raises:
            RuntimeError: the server is gone, or did not answer within `timeout`.
        """
        self.start()
        self.ready(timeout)
        ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
        forked: Future[int] = Future()
        try:
            with self._lock:
                if self._socket is None:
                    raise RuntimeError("the fork server has stopped")
                self._forks.append(forked)
                socket.send_fds(self._socket, [pickle.dumps(("fork", entry))], [theirs.fileno()])
            pid = forked.result(timeout)
        finally:
            theirs.close()
        with self._lock:
            code = self._exits.pop(pid, None)
            if code is None:
                self._on_exit[pid] = on_exit
        if code is not None:  # it ended already
            on_exit(pid, code)
        return pid, Connection(ours.detach())

    def _read(self, control: socket.socket) -> None:
        while True:
            try:
                data = control.recv(MAX_MESSAGE)
            except OSError:
                data = b""
            if not data:
                self._gone()
                return
            message = pickle.loads(data)
            if message[0] == "ready":
                self._ready.set_result(message[2])
            elif message[0] == "forked":
                with self._lock:
                    future = self._forks.pop(0)
                future.set_result(message[1])
            elif message[0] == "exited" and not self._stopping:
                with self._lock:
                    listener = self._on_exit.pop(message[1], None)
                    if listener is None:
                        self._exits[message[1]] = message[2]
                if listener is not None:
                    listener(message[1], message[2])

    def _gone(self) -> None:
        with self._lock:
            waiting, self._forks = self._forks, []
            listeners, self._on_exit = self._on_exit, {}
        if not self._ready.done():
            self._ready.set_exception(RuntimeError("the fork server ended before it was ready"))
        for future in waiting:
            future.set_exception(RuntimeError("the fork server has stopped"))
        if self._stopping:
            return
        for pid, listener in listeners.items():  # its children were killed with it
            listener(pid, -signal.SIGKILL)

    def stop(self, timeout: float = 10.0) -> None:
        """End the server (its remaining children are killed) and reap it."""
        with self._lock:
            self._stopping = True
            process, self._process = self._process, None
            if self._socket is not None:
                with contextlib.suppress(OSError):
                    self._socket.shutdown(socket.SHUT_WR)  # the server sees EOF
        if process is None:
            return
        try:
            process.wait(timeout)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(timeout)


_shared: ForkServer | None = None
_shared_lock = threading.Lock()


def shared() -> ForkServer:
    """This process's fork server (started on first use; stopped when the process exits)."""
    global _shared
    with _shared_lock:
        if _shared is None:
            _shared = ForkServer()
            _shared.start()
            atexit.register(_shared.stop)
        return _shared


# ----------------------------------------------------------------------------------------------
# The server


class _Server:
    """The server's state: its control socket, its children, and the warm-up under way."""

    def __init__(self, control: socket.socket) -> None:
        self.control = control
        self.children: set[int] = set()
        self.warming: int | None = None  # the child that warms the kernels up (compiles them on a cold cache)

    def reap(self, block: bool = False) -> None:
        """Wait for every child that has ended (with `block`, for every child) and tell the API how each did."""
        while self.children or self.warming is not None:
            try:
                pid, status = os.waitpid(-1, 0 if block else os.WNOHANG)
            except ChildProcessError:
                self.children.clear()
                return
            if pid == 0:
                return
            if pid == self.warming:  # the kernels are in numba's cache now: loading them here takes a moment
                self.warming = None
                sys.modules["horde.runs.warm"].warm_up()
                continue
            self.children.discard(pid)
            with contextlib.suppress(OSError):
                self.control.send(pickle.dumps(("exited", pid, os.waitstatus_to_exitcode(status))))


def _lower_priority() -> None:
    """This worker yields the CPU to the API and to the machine's other work, as a niced process (WORKER_NICENESS),
    and competes for it as a process of its own: in a session of its own whose scheduling group (Linux's
    autogroup, where the kernel shares the CPU among sessions first) is niced the same."""
    with contextlib.suppress(OSError):
        os.setsid()
    with contextlib.suppress(OSError):
        Path("/proc/self/autogroup").write_text(str(WORKER_NICENESS))
    with contextlib.suppress(OSError):
        os.nice(WORKER_NICENESS)


def _child(sockets: list[socket.socket], selector: selectors.BaseSelector, entry: Any, fd: int) -> None:
    """In the forked child: drop the server's state, lower the priority, run the worker, exit."""
    code = 0
    try:
        selector.close()
        for own in sockets:
            own.close()
        signal.set_wakeup_fd(-1)
        signal.signal(signal.SIGCHLD, signal.SIG_DFL)
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        _lower_priority()
        entry(ProcessChannel(Connection(fd)) if fd >= 0 else None)
    except BaseException:
        logging.getLogger("horde.runs.worker").exception("a worker ended with an exception")
        code = 1
    finally:
        with contextlib.suppress(BaseException):
            logging.shutdown()
        os._exit(code)


def main(fd: int) -> None:
    """The server: preload, warm up, then fork on request until the API process goes away.

    The warm-up runs first in a child of its own, so that the server forks at once even on a cold numba cache
    (compiling every kernel takes a minute or more): a worker forked meanwhile loads or compiles what it
    needs itself, and says so ("preparing the learning kernels"); once the child is done, the server loads the
    kernels from the cache, and every worker forked after that starts with them loaded.
    """
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    server = _Server(socket.socket(fileno=fd))
    control = server.control
    began = time.perf_counter()
    for name in PRELOAD:
        __import__(name)
    wakeup_r, wakeup_w = socket.socketpair()
    wakeup_r.setblocking(False)
    wakeup_w.setblocking(False)
    signal.set_wakeup_fd(wakeup_w.fileno())
    signal.signal(signal.SIGCHLD, lambda *_: None)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    selector = selectors.DefaultSelector()
    selector.register(control, selectors.EVENT_READ)
    selector.register(wakeup_r, selectors.EVENT_READ)
    server.warming = os.fork()
    if server.warming == 0:
        _child([control, wakeup_r, wakeup_w], selector, lambda channel: sys.modules["horde.runs.warm"].warm_up(), -1)
    control.send(pickle.dumps(("ready", os.getpid(), time.perf_counter() - began)))
    while True:  # one thread: every child starts from a process with no other thread
        for key, _ in selector.select():
            if key.fileobj is wakeup_r:
                with contextlib.suppress(BlockingIOError):
                    wakeup_r.recv(4096)
                server.reap()
                continue
            try:
                data, fds, _, _ = socket.recv_fds(control, MAX_MESSAGE, 1)
            except OSError:
                data, fds = b"", []
            if not data:  # the API process has gone
                for pid in [*server.children, *([server.warming] if server.warming else [])]:
                    with contextlib.suppress(OSError):
                        os.kill(pid, signal.SIGKILL)
                server.reap(block=True)
                return
            _, entry = pickle.loads(data)
            pid = os.fork()
            if pid == 0:
                _child([control, wakeup_r, wakeup_w], selector, entry, fds[0])
            os.close(fds[0])
            server.children.add(pid)
            control.send(pickle.dumps(("forked", pid)))
