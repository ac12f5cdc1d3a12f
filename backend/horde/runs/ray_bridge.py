"""The Ray bridge: the process that hosts workers as Ray actors, wherever the cluster has room.

A server given a cluster (HORDE_RAY_ADDRESS) runs its live runs, stream runs and protocol jobs there. The
API process never joins Ray (a Ray driver dies with Ray): this bridge, a worker process of the fork server,
is the cluster's driver. For each worker it makes a `RunHost` actor, which runs the worker's loop in a
thread over an in-memory channel (`thread_host.QueueChannel`), exactly the loop a local worker process runs;
the bridge carries the messages both ways, in envelopes keyed by worker:

    API -> bridge   Open(key, entry, init)   an actor of `cpus` CPUs runs entry(channel); init is its first message
                    Envelope(key, message)   to the worker (numbered, so that the actor keeps their order)
                    Close(key)               kill the actor
    bridge -> API   Envelope(key, message)   from the worker (its Ready says on which node it runs)
                    Ended(key, reason)       the worker ended (asked to, or its actor died: why)

One thread reads the API's messages and hands them to the actors; the main thread keeps one long poll
(`take`) outstanding per actor and forwards what comes back. When Ray goes away, the bridge ends (Ray ends
its driver), and the API process fails the runs it hosted, saying so.
"""

from __future__ import annotations

import contextlib
import logging
import os
import threading
from dataclasses import replace
from typing import Any

from horde.runs import messages as m
from horde.runs.thread_host import QueueChannel, run_in_thread
from horde.runs.worker_life import Channel, Heart

log = logging.getLogger(__name__)

TAKE_SECONDS = 0.5  # an actor's long poll waits this long for messages at most
PLACE_SECONDS = 300.0  # an actor may take this long to be placed and started


class RunHost:
    """The actor's body: a worker's loop in a thread, and its channel's two ends as the actor's methods."""

    def __init__(self, entry: Any) -> None:
        import ray

        self.channel = QueueChannel()
        self.node = ray.get_runtime_context().get_node_id()
        self._expected = 0
        self._held: dict[int, Any] = {}
        self._lock = threading.Lock()
        run_in_thread(entry, self.channel, "horde-actor-worker")

    def deliver(self, seq: int, message: Any) -> None:
        """A message from the API, delivered in the order it was sent (calls may run out of order)."""
        with self._lock:
            self._held[seq] = message
            while self._expected in self._held:
                self.channel.deliver(self._held.pop(self._expected))
                self._expected += 1

    def take(self, wait: float) -> tuple[list[Any], bool, str]:
        """What the worker has sent (waiting up to `wait` seconds for something), whether it has ended, and what
        its loop raised if it did."""
        ended = self.channel.ended.is_set()
        return self.channel.take(0.0 if ended else wait), ended, self.channel.error

    def where(self) -> tuple[int, str]:
        return os.getpid(), self.node


class _Actor:
    """The bridge's record of one hosted worker."""

    def __init__(self, handle: Any, node: str) -> None:
        self.handle = handle
        self.node = node
        self.seq = 0
        self.lock = threading.Lock()


class Bridge:
    """The bridge's state: the cluster's handle, the actors it hosts, and one outstanding long poll for each."""

    def __init__(self, channel: Channel, init: m.BridgeInit, ray: Any) -> None:
        self.channel = channel
        self.init = init
        self.ray = ray
        self.host = ray.remote(RunHost)
        self.actors: dict[int, _Actor] = {}
        self.polls: dict[Any, int] = {}  # outstanding take -> key
        self.lock = threading.Lock()
        self.wake = threading.Event()
        self.turns = 0

    def read(self) -> None:
        """The API's messages, handed to the actors; the API's end (or its Shutdown) ends the bridge."""
        while True:
            try:
                message = self.channel.recv()
            except (EOFError, OSError):
                message = None
            if message is None or isinstance(message, m.Call):  # Shutdown: the actors end with their driver
                with contextlib.suppress(Exception):
                    self.ray.shutdown()
                os._exit(0)
            try:
                self.handle(message)
            except Exception:
                log.exception("the Ray bridge could not hand a message on")

    def handle(self, message: Any) -> None:
        if isinstance(message, m.Open):
            threading.Thread(target=self.open, args=(message,), name="horde-bridge-open", daemon=True).start()
        elif isinstance(message, m.Envelope):
            with self.lock:
                actor = self.actors.get(message.key)
            if actor is not None:
                self.send_to(actor, message.message)
        elif isinstance(message, m.Close):
            with self.lock:
                actor = self.actors.pop(message.key, None)
            if actor is not None:
                self.ray.kill(actor.handle, no_restart=True)
                self.channel.send(m.Ended(message.key))

    def open(self, message: m.Open) -> None:
        """Make the actor (in a thread of its own: it waits for room in the cluster, and for the actor's start)."""
        handle: Any = self.host.options(num_cpus=self.init.cpus, max_concurrency=4).remote(message.entry)
        try:
            _, node = self.ray.get(handle.where.remote(), timeout=PLACE_SECONDS)
        except Exception as exc:
            self.ray.kill(handle, no_restart=True)
            self.channel.send(m.Ended(message.key, f"no actor within {PLACE_SECONDS:g} s ({type(exc).__name__}): "
                                                   "is there room in the cluster?"))  # fmt: skip
            return
        actor = _Actor(handle, node)
        with self.lock:
            self.actors[message.key] = actor
        self.send_to(actor, message.init)
        with self.lock:
            self.polls[handle.take.remote(TAKE_SECONDS)] = message.key
        self.wake.set()

    def send_to(self, actor: _Actor, message: Any) -> None:
        with actor.lock:
            actor.handle.deliver.remote(actor.seq, message)
            actor.seq += 1

    def carry(self) -> None:
        """Forward what the actors' long polls bring back, and poll again (the main thread, for ever)."""
        while True:
            self.turns += 1
            with self.lock:
                outstanding = list(self.polls)
            if not outstanding:
                self.wake.wait(0.5)
                self.wake.clear()
                continue
            ready, _ = self.ray.wait(outstanding, num_returns=1, timeout=0.1)
            for ref in ready:
                self.forward(ref)

    def forward(self, ref: Any) -> None:
        with self.lock:
            key = self.polls.pop(ref)
            actor = self.actors.get(key)
        if actor is None:
            return  # closed meanwhile
        try:
            messages, ended, error = self.ray.get(ref)
        except Exception as exc:  # the actor died: its process, or its node
            with self.lock:
                self.actors.pop(key, None)
            self.channel.send(m.Ended(key, f"its Ray actor died: {type(exc).__name__}: {str(exc)[:300]}"))
            return
        for message in messages:
            if isinstance(message, m.Ready):
                message = replace(message, node=actor.node)
            self.channel.send(m.Envelope(key, message))
        if ended:
            with self.lock:
                self.actors.pop(key, None)
            self.ray.kill(actor.handle, no_restart=True)
            self.channel.send(m.Ended(key, f"its loop raised {error}" if error else ""))
        else:
            with self.lock:
                self.polls[actor.handle.take.remote(TAKE_SECONDS)] = key


def serve_bridge(channel: Channel) -> None:
    """The bridge (the fork server's entry): join the cluster, then carry messages until the API goes away."""
    init = channel.recv()
    assert isinstance(init, m.BridgeInit)
    os.environ.update(init.env)
    import ray

    try:
        ray.init(address=init.address, log_to_driver=False, namespace="horde")
    except Exception as exc:
        channel.send(m.Ready(failure=m.failure_of(exc), pid=os.getpid()))
        return
    bridge = Bridge(channel, init, ray)
    threading.Thread(target=bridge.read, name="horde-bridge-reader", daemon=True).start()
    Heart(channel, lambda: bridge.turns)
    channel.send(m.Ready(pid=os.getpid()))
    bridge.carry()
