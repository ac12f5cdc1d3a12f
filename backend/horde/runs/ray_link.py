"""Workers as Ray actors, API side: `RayExecutor` has the face of `executor.ProcessExecutor` (`spawn`, `stop`).

It starts the Ray bridge (`ray_bridge.py`, a worker process of the fork server that is the cluster's driver)
on first use, and again after it ended; each worker it spawns is an actor of the cluster, reached through the
bridge: a `WorkerLink` whose messages travel in envelopes. The bridge's end (Ray went away: its driver ends)
ends every worker it hosted, with that reason, so that their runs fail alone and say why; the server stays up.
"""

from __future__ import annotations

import contextlib
import itertools
import logging
import os
import threading
from collections.abc import Callable
from typing import Any

from horde.runs import messages as m
from horde.runs.executor import ProcessExecutor
from horde.runs.link import Listener, WorkerGoneError, WorkerLink
from horde.runs.ray_bridge import serve_bridge

log = logging.getLogger(__name__)

CLOSE_SECONDS = 10.0  # a closed actor's end is awaited this long


class RayExecutor:
    """Workers as actors of the Ray cluster at `address`.

    Args:
        processes: the local executor, whose fork server starts the bridge.
        address: the cluster's address (host:port).
        cpus: CPUs each actor asks of the cluster.
    """

    kind = "ray"

    def __init__(self, processes: ProcessExecutor, address: str, cpus: float = 1.0) -> None:
        self.processes = processes
        self.address = address
        self.cpus = cpus
        self._bridge: WorkerLink | None = None
        self._links: dict[int, WorkerLink] = {}
        self._keys = itertools.count(1)
        self._lock = threading.Lock()

    @property
    def stall_seconds(self) -> float:
        return self.processes.stall_seconds

    def start(self) -> None:
        self.processes.start()

    def _ensure_bridge(self) -> WorkerLink:
        """The running bridge, started (and joined to the cluster) first if there is none.

        Raises:
            the bridge's failure to join the cluster (a ConflictError saying why).
        """
        with self._lock:
            bridge = self._bridge
            if bridge is not None and bridge.alive:
                return bridge
            env = {k: v for k, v in os.environ.items() if k.startswith("RAY_")}  # the cluster's token, ...
            bridge = self.processes.spawn(serve_bridge, m.BridgeInit(self.address, self.cpus, env), _Bridge(self))
            self._bridge = bridge
        ready = bridge.wait_ready()
        if ready.failure is not None:
            bridge.stop()
            m.raise_failure(m.Failure("conflict", f"the Ray cluster at {self.address} cannot be joined: "
                                                  f"{ready.failure.message}"))  # fmt: skip
        return bridge

    def spawn(self, entry: Callable[[Any], None], init: m.WorkerInit, listener: Listener) -> WorkerLink:
        """A worker running `entry` as an actor of the cluster, sent `init`; its Ready says on which node."""
        bridge = self._ensure_bridge()
        key = next(self._keys)
        link = WorkerLink("ray", lambda message: bridge.send(m.Envelope(key, message)), listener, self._stop_worker)
        link.key = key  # type: ignore[attr-defined]
        with self._lock:
            self._links[key] = link
        self.processes.switchboard.watch(link)
        bridge.send(m.Open(key, entry, init))
        return link

    def _stop_worker(self, link: WorkerLink) -> None:
        """Kill the worker's actor (asked to end already, or not), once it has had a moment to end by itself."""
        link.stopping = True
        if link.ended.wait(2.0):
            return
        bridge = self._bridge
        if bridge is not None and bridge.alive:
            bridge.send(m.Close(link.key))  # type: ignore[attr-defined]
        if not link.ended.wait(CLOSE_SECONDS):
            link.end("stopped")

    def deliver(self, message: m.FromWorker) -> None:
        """A message of the bridge (the switchboard's thread)."""
        if isinstance(message, m.Envelope):
            with self._lock:
                link = self._links.get(message.key)
            if link is not None:
                link.deliver(message.message)
        elif isinstance(message, m.Ended):
            with self._lock:
                link = self._links.pop(message.key, None)
            if link is not None:
                link.end(message.reason or "exited")

    def bridge_ended(self, reason: str) -> None:
        """The bridge has ended (Ray went away, or it was killed): every worker it hosted has ended with it."""
        with self._lock:
            links, self._links = list(self._links.values()), {}
        for link in links:
            link.end(f"its Ray bridge ended ({reason}): Ray may have gone away")

    def stop(self) -> None:
        """End the bridge (its actors end with it: they are its driver's)."""
        with self._lock:
            bridge, self._bridge = self._bridge, None
        if bridge is not None:
            bridge.stopping = True
            with contextlib.suppress(WorkerGoneError):
                bridge.send(m.Call(0, m.Shutdown()))
            bridge.stop()


class _Bridge:
    """What the bridge says (`link.Listener`): envelopes for the workers it hosts, and its own end."""

    def __init__(self, executor: RayExecutor) -> None:
        self.executor = executor

    def on_message(self, message: m.FromWorker) -> None:
        self.executor.deliver(message)

    def on_reply(self, command: m.Command | None, reply: m.Reply) -> None:
        pass

    def on_exit(self, reason: str) -> None:
        log.error("the Ray bridge ended: %s", reason)
        self.executor.bridge_ended(reason)

    def on_stall(self, seconds: float, doing: str) -> None:
        pass
