"""What every worker has, whatever it runs (a live run, a stream run, a protocol job, a study's driver): its channel
to the API process, its heartbeat, and the crash that tests may ask of it.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import threading
import time
from collections.abc import Callable
from typing import Protocol

from horde.runs import messages as m


class Channel(Protocol):
    """The worker's end of its connection to the API process."""

    def poll(self, timeout: float | None) -> bool:
        """Whether a message waits (True too when the API process has gone: `recv` then raises EOFError)."""
        ...

    def recv(self) -> m.ToWorker: ...
    def send(self, message: m.FromWorker) -> None:
        """Send a message (any thread)."""
        ...


class GoneError(Exception):
    """The API process closed the channel: the worker ends."""


class Heart:
    """The worker's heartbeat: a thread that sends `Beat` every BEAT_SECONDS with the main loop's progress."""

    def __init__(self, channel: Channel, progress: Callable[[], int]) -> None:
        self.channel = channel
        self.progress = progress
        self.doing = ""
        self.since = 0.0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._beat, name="horde-heart", daemon=True)
        self._thread.start()

    def busy(self, doing: str) -> None:
        self.doing, self.since = doing, time.monotonic()

    def idle(self) -> None:
        self.doing = ""

    def _beat(self) -> None:
        while not self._stop.wait(m.BEAT_SECONDS):
            doing = self.doing
            busy = time.monotonic() - self.since if doing else 0.0
            with contextlib.suppress(Exception):  # the channel closed: the main loop ends too
                self.channel.send(m.Beat(self.progress(), doing, busy))

    def stop(self) -> None:
        self._stop.set()


def crash(how: m.CrashKind) -> None:
    """Die as a crash would, or stop answering (tests only: `RunInit.hooks`)."""
    if how == "segv":
        ctypes.string_at(0)  # a read of address 0: SIGSEGV
    elif how == "abort":
        os.abort()
    elif how == "exit":
        os._exit(3)
    while True:  # "hang": the main loop never turns again
        time.sleep(1.0)
