"""A bounded, thread-safe log of what happened in a run (episodes, status changes, demons, errors)."""

from __future__ import annotations

import threading
from collections import deque
from dataclasses import dataclass
from typing import Literal

EventKind = Literal["status", "episode", "demon", "error"]
# The events a run's state carries at most, the latest: GET .../state, a step's answer, and each message
# of the stream (a run at full speed ends hundreds of episodes between two messages, and their events
# would make every message tens of kilobytes; a gap in the events' `seq` says that some were left out).
RECENT_EVENTS = 20


@dataclass(frozen=True)
class Event:
    """One thing that happened; `seq` increases by one per event of the run."""

    seq: int
    step: int
    episode: int
    kind: EventKind
    message: str
    value: float | None = None  # the return of an episode, where kind == "episode"


class EventLog:
    """The last `capacity` events of a run."""

    def __init__(self, capacity: int = 256) -> None:
        self._events: deque[Event] = deque(maxlen=capacity)
        self._lock = threading.Lock()
        self._seq = 0

    @property
    def last_seq(self) -> int:
        """The sequence number of the newest event (0 before any)."""
        return self._seq

    def add(self, step: int, episode: int, kind: EventKind, message: str, value: float | None = None) -> Event:
        with self._lock:
            self._seq += 1
            event = Event(self._seq, step, episode, kind, message, value)
            self._events.append(event)
        return event

    def skip(self, count: int) -> None:
        """Count `count` events that were left out (a worker sends the last ones only): `seq` shows the gap."""
        with self._lock:
            self._seq += max(0, count)

    def since(self, seq: int, limit: int = 256) -> list[Event]:
        """Events newer than `seq`, at most the last `limit` of them."""
        with self._lock:
            found = [e for e in self._events if e.seq > seq]
        return found[-limit:]

    def recent(self, limit: int = RECENT_EVENTS) -> list[Event]:
        with self._lock:
            return list(self._events)[-limit:]
