"""Stream runs: a stream world's Horde learning the records that clients push, in order, one run at a time.

`StreamRun` wraps a `RecordLearner` (horde.worlds.records) behind a lock, so that the REST route and the
WebSocket route (server/routes/records.py) can both feed it: every batch is checked and learned whole,
in the order it arrives. `StreamRuns` is the server's registry of them (bounded; kept in memory only).
"""

from __future__ import annotations

import threading
import time
import uuid
from collections import deque
from dataclasses import dataclass
from typing import Any

import numpy as np

from horde.runs.errors import BusyError, FieldProblem, NotFoundError, SpecError
from horde.spec import RunSpec
from horde.worlds.phase_plane import Axis, axis_of, phase_plane
from horde.worlds.records import RecordLearner, Records, Refusal

MAX_STREAM_RUNS = 16
MAX_RECORDS_PER_BATCH = 10_000
TRAIL = 500  # recent observations kept for the phase plane


@dataclass(frozen=True)
class PushResult:
    received: int  # records received in all, good or refused
    learned: int  # good records taken in, in all
    refused: list[Refusal]  # this batch's
    predictions: np.ndarray  # [D] at the last good observation
    seconds: float  # time spent learning this batch


class StreamRun:
    """One stream world's Horde and its counters.

    Args:
        run_id: the id the routes name it by.
        spec: a run spec whose world is of kind "stream".
    """

    def __init__(self, run_id: str, spec: RunSpec) -> None:
        self.id = run_id
        self.spec = spec
        self.learner = RecordLearner(spec)
        self.names = self.learner.loop.horde.names
        self.created = time.time()
        self._lock = threading.Lock()
        self._trail: deque[np.ndarray] = deque(maxlen=TRAIL)  # the last good observations [S]

    def check(self, items: list[Any]) -> tuple[Records, list[Refusal]]:
        """Check a batch without learning it (REST batches are all-or-nothing)."""
        from horde.worlds.records import check_records

        return check_records(self.learner.world, items, list(range(len(items))))

    def push(self, items: list[Any]) -> PushResult:
        """Check a batch and learn its good records, in order (refused ones restart the stream after them)."""
        with self._lock:
            began = time.perf_counter()
            records, refused = self.learner.check(items)
            self.learner.learn(records)
            self._trail.extend(records.observations[-TRAIL:])
            return PushResult(self.learner.received, self.learner.learned, refused, self.learner.predictions(),
                              time.perf_counter() - began)  # fmt: skip

    def phase_plane(self, demon: str, x: str, y: str, resolution: int) -> tuple[Axis, Axis, np.ndarray, np.ndarray]:
        """(x axis, y axis, [R, R] the demon's values over the plane, [N, 2] the recent (x, y) readings).

        Raises:
            SpecError: an unknown demon or sensor (422 naming the query parameter).
        """
        horde = self.learner.loop.horde
        if demon not in horde.index:
            raise SpecError([FieldProblem(("query", "demon"), f"no demon {demon!r} in this run")])
        axes = []
        for field, sensor in (("x", x), ("y", y)):
            try:
                axes.append(axis_of(horde, sensor))
            except ValueError as exc:
                raise SpecError([FieldProblem(("query", field), str(exc))]) from None
        with self._lock:
            state = self.learner.loop.horde_state()
            trail = np.array(self._trail).reshape(-1, len(self.learner.world.sensors))
        held = trail[-1] if len(trail) else np.zeros(len(self.learner.world.sensors))
        names = self.learner.world.sensor_names()
        values = phase_plane(horde, state, demon, axes[0], axes[1], held, resolution)
        return axes[0], axes[1], values, trail[:, [names.index(x), names.index(y)]]

    def status(self) -> PushResult:
        with self._lock:
            return PushResult(self.learner.received, self.learner.learned, [], self.learner.predictions(), 0.0)


class StreamRuns:
    """The server's stream runs by id (at most MAX_STREAM_RUNS at once)."""

    def __init__(self) -> None:
        self._runs: dict[str, StreamRun] = {}
        self._lock = threading.Lock()

    def create(self, spec: RunSpec) -> StreamRun:
        """A new stream run. Raises SpecError (422 at world.kind) for another world kind, BusyError when full."""
        if spec.world.kind != "stream":
            message = f"a stream run needs world.kind = 'stream', not {spec.world.kind!r}"
            raise SpecError([FieldProblem(("body", "world", "kind"), message)])
        with self._lock:
            if len(self._runs) >= MAX_STREAM_RUNS:
                raise BusyError(f"{MAX_STREAM_RUNS} stream runs exist already; delete one first")
            run = StreamRun(uuid.uuid4().hex[:12], spec)
            self._runs[run.id] = run
            return run

    def get(self, run_id: str) -> StreamRun:
        with self._lock:
            run = self._runs.get(run_id)
        if run is None:
            raise NotFoundError(f"no stream run {run_id!r}")
        return run

    def delete(self, run_id: str) -> None:
        with self._lock:
            if self._runs.pop(run_id, None) is None:
                raise NotFoundError(f"no stream run {run_id!r}")

    def list(self) -> list[StreamRun]:
        with self._lock:
            return list(self._runs.values())
