"""A stream run's learning, in its worker: a stream world's Horde learning the records that clients push, in order.

`StreamLearning` wraps a `RecordLearner` (horde.worlds.records): every batch is checked and learned whole, in
the order it arrives, and the recent records are kept for the strip chart and the phase plane. It lives in
the stream run's worker (`job_workers.StreamWorker`); the API process holds a `stream_run.StreamRun` that
sends it the records.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from dataclasses import dataclass
from typing import Any

import numpy as np

from horde.core.learner import Readout
from horde.runs.errors import FieldProblem, SpecError
from horde.runs.stream_snapshot import StreamSnapshot, capture_stream
from horde.spec import RunSpec
from horde.worlds.phase_plane import Axis, axis_of, phase_plane
from horde.worlds.records import RecordLearner, Records, Refusal

MAX_RECORDS_PER_BATCH = 10_000
TRAIL = 500  # recent observations kept for the phase plane
HISTORY = 2000  # recent records kept (observations and every demon's prediction) for the strip chart
HISTORY_CELLS = 4_000_000  # at most this many predictions kept (records x demons): fewer records for big Hordes


class RecentRecords:
    """A ring of the last `capacity` good records: observations [S], every demon's prediction [D] made on
    observing it, its number in the stream, and whether the stream restarted there (observed afresh)."""

    def __init__(self, capacity: int, sensors: int, demons: int) -> None:
        self.capacity = capacity
        self.observations = np.zeros((capacity, sensors))
        self.predictions = np.zeros((capacity, demons))
        self.numbers = np.zeros(capacity, dtype=np.int64)
        self.restarts = np.zeros(capacity, dtype=bool)
        self.size = 0
        self._next = 0  # where the next row goes

    def add(self, observations: np.ndarray, predictions: np.ndarray, numbers: np.ndarray, restarts: np.ndarray) -> None:
        n = len(observations)
        if n > self.capacity:
            observations, predictions = observations[-self.capacity :], predictions[-self.capacity :]
            numbers, restarts = numbers[-self.capacity :], restarts[-self.capacity :]
            n = self.capacity
        rows = (self._next + np.arange(n)) % self.capacity
        self.observations[rows], self.predictions[rows] = observations, predictions
        self.numbers[rows], self.restarts[rows] = numbers, restarts
        self._next = (self._next + n) % self.capacity
        self.size = min(self.size + n, self.capacity)

    def last(self, n: int, demons: list[int]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The last n rows, oldest first: (observations [n, S], predictions [n, len(demons)] of those demon
        indices only, numbers [n], restarts [n]); copies (fancy indexing)."""
        n = min(n, self.size)
        rows = (self._next - n + np.arange(n)) % self.capacity
        columns = np.asarray(demons, dtype=np.int64)
        return self.observations[rows], self.predictions[np.ix_(rows, columns)], self.numbers[rows], self.restarts[rows]


@dataclass(frozen=True)
class PushResult:
    received: int  # records received in all, good or refused
    learned: int  # good records taken in, in all
    refused: list[Refusal]  # this batch's
    predictions: np.ndarray  # [D] at the last good observation
    seconds: float  # time spent learning this batch


@dataclass(frozen=True)
class StreamHistory:
    numbers: np.ndarray  # [N] each record's number in the stream (0 = the first ever sent)
    sensors: dict[str, np.ndarray]  # name -> [N] readings
    predictions: dict[str, np.ndarray]  # demon -> [N] its prediction on observing each record
    returns: dict[str, np.ndarray | None]  # demon -> [N] the realised return after it (nan: not yet known)


class StreamLearning:
    """One stream world's Horde and its counters.

    Args:
        run_id: the id the routes name it by.
        spec: a run spec whose world is of kind "stream".
        learner: the learner to go on with (an imported snapshot's; default a fresh one).
    """

    def __init__(self, run_id: str, spec: RunSpec, learner: RecordLearner | None = None) -> None:
        self.id = run_id
        self.spec = spec
        self.learner = learner if learner is not None else RecordLearner(spec)
        self.names = self.learner.loop.horde.names
        self._lock = threading.Lock()
        self._trail: deque[np.ndarray] = deque(maxlen=TRAIL)  # the last good observations [S]
        demons = len(self.names)
        self.recent = RecentRecords(max(100, min(HISTORY, HISTORY_CELLS // max(demons, 1))),
                                    len(self.learner.world.sensors), demons)  # fmt: skip

    def check(self, items: list[Any]) -> tuple[Records, list[Refusal]]:
        """Check a batch without learning it (REST batches are all-or-nothing)."""
        from horde.worlds.records import check_records

        return check_records(self.learner.world, items, list(range(len(items))))

    def push(self, items: list[Any], whole: bool = False) -> PushResult:
        """Check a batch and learn its good records, in order (refused ones restart the stream after them); with
        `whole`, a batch with any refused record is not learned at all."""
        if whole:
            _, refused = self.check(items)
            if refused:
                return PushResult(self.learner.received, self.learner.learned, refused, self.learner.predictions(), 0.0)
        with self._lock:
            began = time.perf_counter()
            first = self.learner.received  # the number of this batch's first record
            fresh = self.learner._pending is None  # the first good record is observed afresh
            records, refused = self.learner.check(items)
            kept = self.learner.learn(records, keep_predictions=True)
            self._trail.extend(records.observations[-TRAIL:])
            if len(records) and kept is not None:
                good = np.ones(len(items), dtype=bool)
                good[[r.index - first for r in refused]] = False
                restarts = np.zeros(len(records), dtype=bool)
                restarts[[g for g in records.gaps if g < len(records)]] = True
                restarts[0] = restarts[0] or fresh
                self.recent.add(records.observations, kept, first + np.flatnonzero(good), restarts)
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

    def history(self, sensors: list[str], demons: list[str], last: int) -> StreamHistory:
        """The last `last` good records' `sensors`, and each of `demons`' predictions beside the realised
        discounted return that followed it, computed afterwards from the records after it (nan where the
        stream has not yet gone far enough for the rest of the return to weigh less than TAIL_WEIGHT, or
        where a refused record broke the stream before it did; None for a demon whose question reads other
        demons' predictions, which the records do not hold).

        Raises:
            SpecError: an unknown sensor or demon (422 naming the query parameter).
        """
        from horde.spec import expr_predictions
        from horde.worlds.log_run import TAIL_WEIGHT, realised_returns

        names = self.learner.world.sensor_names()
        for field, asked, known in (("sensors", sensors, names), ("demons", demons, self.names)):
            unknown = [a for a in asked if a not in known]
            if unknown:
                message = f"unknown {field[:-1]} {unknown[0]!r} (known: {', '.join(known[:20])})"
                raise SpecError([FieldProblem(("query", field), message)])
        with self._lock:
            columns = [self.names.index(d) for d in demons]
            observations, predictions, numbers, restarts = self.recent.last(last, columns)
        index = {d.name: i for i, d in enumerate(self.spec.demons)}
        readable = [d for d in demons if not any(expr_predictions(e) for e in
                    (self.spec.demons[index[d]].cumulant, self.spec.demons[index[d]].outcome,
                     self.spec.demons[index[d]].continuation))]  # fmt: skip
        returns = {d: np.full(len(numbers), np.nan) for d in readable}
        if readable and len(numbers):
            subset = self.spec.model_copy(update={"demons": [self.spec.demons[index[d]] for d in readable]})
            starts = [*np.flatnonzero(restarts[1:]) + 1]
            for lo, hi in zip([0, *starts], [*starts, len(numbers)], strict=True):
                g, tail = realised_returns(subset, observations[lo:hi])
                for k, d in enumerate(readable):
                    returns[d][lo:hi] = np.where(tail[:, k] < TAIL_WEIGHT, g[:, k], np.nan)
        return StreamHistory(
            numbers=numbers,
            sensors={s: observations[:, names.index(s)] for s in sensors},
            predictions={d: predictions[:, k] for k, d in enumerate(demons)},
            returns={d: returns.get(d) for d in demons},
        )

    def readout(self) -> tuple[Readout, np.ndarray]:
        """Every demon's numbers at the last observation (the demon table's), and [D] their step sizes now."""
        with self._lock:
            loop = self.learner.loop
            return loop.readout(), loop.engine.effective_step_sizes()

    def snapshot(self) -> StreamSnapshot:
        """The learner's state now, between two batches (`stream_snapshot`)."""
        with self._lock:
            return capture_stream(self.learner)

    def status(self) -> PushResult:
        with self._lock:
            return PushResult(self.learner.received, self.learner.learned, [], self.learner.predictions(), 0.0)
