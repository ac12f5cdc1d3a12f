"""A run's recorder, in its worker: history rows, the views it publishes, and the saves it hands to the API process.

The worker's main loop calls the recorder between two batches of steps (never while learning), with the
session whose state it records. Nothing here reaches a reader directly: rows, views and events go out as one
`messages.Update` (at most every PUBLISH_INTERVAL while running), saves as `messages.Save` (the API process
writes them to the store). A save that a command waits for is returned to the worker, which sends it with
the command's reply; a periodic snapshot is encoded in the recorder's own thread and sent when it is ready,
one at a time: the next waits until the API process has said the last is written (`SaveDone`).
"""

from __future__ import annotations

import itertools
import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np

from horde.core.engine.layout import FOREVER
from horde.core.simulation import Simulation
from horde.core.world import WorldState
from horde.runs.history import QUANTITIES, History, quantities_of
from horde.runs.messages import EventData, FromWorker, PublishedView, Rows, Save, SaveDone, Update
from horde.runs.run_setup import Limits
from horde.runs.session import RunSession
from horde.runs.snapshot import encode_frozen, freeze, to_bytes
from horde.runs.store import RunRecord
from horde.spec import RunSpec
from horde.worlds.state_values import StateErrors, state_errors

log = logging.getLogger(__name__)

# A periodic snapshot waits this many times the last one's encoding and writing: encoding holds the worker's GIL,
# and at three times (a third of the time) a live nexting run learned 16 steps/s, not 30.
SNAPSHOT_DUTY_RATIO = 10
PUBLISH_INTERVAL = 1.0 / 30.0  # while running, views are published at most this often (the streams send 30 a second)
MAX_PUBLISH_INTERVAL = 0.5  # ... and at least this often, however long a view takes to make
# Bytes a second of history rows and views that one run sends at most: a Horde of 9,000 demons makes a row of
# 360 kB, and rows at every 5 ms would be 72 MB/s for the API process to take in. Beyond the budget, rows and
# views are spaced out (a full-speed run's history is a sample anyway).
ROW_BYTES_PER_SECOND = 8_000_000
VIEW_BYTES_PER_SECOND = 16_000_000
VIEW_ARRAYS = 7  # [D] arrays in a published view
# RMSVE and RMSPBE (a forward pass over every state) are measured on a history row at most this often while a run
# runs, and at most at a twentieth of the main loop's time (random-walk-1000's three demons: 0.5 ms a
# measurement, docs/performance.md); the rows between carry the latest measurement. The last row of a step
# command or a pause is always measured.
STATE_ERRORS_INTERVAL = 0.1


@dataclass(frozen=True)
class SnapshotCost:
    """What the latest periodic snapshot cost: freezing it in the main loop, encoding it after, writing it in the
    API process."""

    freeze_seconds: float = 0.0
    encode_seconds: float = 0.0
    write_seconds: float = 0.0
    bytes: int = 0


class Recorder:
    """History rows, publication and saves of one run in its worker.

    Args:
        run_id: the run's id.
        limits: the server's limits (history size, intervals).
        send: sends a message to the API process (thread-safe).
        created_at: the run's creation time.
        names: the demons, for the history.
        persist: whether saves are made at all (a server with a store).
        spec: the run's spec (what its history rows hold: `history.quantities_of`); default: no state errors.
    """

    def __init__(self, run_id: str, limits: Limits, send: Callable[[FromWorker], None], created_at: float,
                 names: list[str], persist: bool = True, spec: RunSpec | None = None) -> None:  # fmt: skip
        self.id = run_id
        self.limits = limits
        self.send = send
        self.created_at = created_at
        self.persist_saves = persist
        self.quantities = quantities_of(spec) if spec is not None else QUANTITIES
        self.history = History(names, limits.history, limits.history_every, self.quantities)
        self.snapshot_cost = SnapshotCost()
        self._rows: list[tuple[int, np.ndarray]] = []  # rows not yet sent: (step, [Q, D])
        self._history: Literal["", "remap", "new"] = ""
        self._sent_event = 0  # the seq of the last event sent
        self._seq = 0
        self._save_ids = itertools.count(1)
        self._pending: int | None = None  # the periodic save being encoded or written
        self._pending_lock = threading.Lock()
        self._last_row = -FOREVER  # no row yet
        self._next_row = 0.0
        self._next_publish = 0.0
        self._last_snapshot = time.monotonic()
        self._encoder: threading.Thread | None = None
        self._status = ""  # of the latest view published (a change is published at once)
        self._diverged = 0  # demons diverged at the latest divergence check
        self._spec: object = None
        self._spec_text = ""
        self._errors: tuple[object, object, StateErrors | None] = (None, None, None)  # for (Horde, spec)
        self._latest_errors: tuple[np.ndarray, np.ndarray] | None = None  # [D] RMSVE and RMSPBE
        self._next_errors = 0.0
        self._measured_at = -1  # the step of the latest measurement

    # ------------------------------------------------------------------------------------------
    # History

    def maybe_record(self, session: RunSession) -> None:
        """A row when `history.every` steps and `limits.history_interval` seconds have passed since the last:
        every step of a run paced by hz (up to 1/interval steps per second), a sample at full speed."""
        if session.sim.total_steps - self._last_row < self.history.every:
            return
        if session.paced_for_rows() or time.monotonic() >= self._next_row:  # a paced run's burst of catching up too
            self.record(session)

    def record(self, session: RunSession, measure: bool = False) -> None:
        """A history row now; `measure`: with RMSVE and RMSPBE measured at this row's weights (else when due)."""
        sim = session.sim
        out = sim.readout()  # O(D): no weights are copied
        prediction = np.where(out.diverged, np.nan, out.prediction)  # [D] a frozen demon's 0s are no answer: null
        quantities = [prediction, out.cumulant, out.delta, out.rupee, out.ude]
        if len(self.quantities) > len(quantities):
            quantities.extend(self._state_errors(session, measure))
        row = np.stack(quantities)  # [Q, D]
        if self._rows and self._rows[-1][0] == sim.total_steps:  # measured again at the same step: one row
            self._rows.pop()
        self._rows.append((sim.total_steps, row))
        if len(self._rows) > self.history.rows:  # older ones would be overwritten in the API's ring anyway
            del self._rows[: len(self._rows) - self.history.rows]
        self._last_row = sim.total_steps
        spacing = row.nbytes / ROW_BYTES_PER_SECOND
        self._next_row = time.monotonic() + max(self.limits.history_interval, spacing)

    def measure_end(self, session: RunSession) -> None:
        """After a step command or a pause: the last row at the run's step, with RMSVE and RMSPBE measured there
        (nothing on a world without them)."""
        if len(self.quantities) > len(QUANTITIES) and self._measured_at != session.sim.total_steps:
            self.record(session, measure=True)

    def _state_errors(self, session: RunSession, measure: bool) -> tuple[np.ndarray, np.ndarray]:
        """[D] RMSVE and [D] RMSPBE: measured now when asked or due, else the latest measurement."""
        sim = session.sim
        D = sim.horde.num_demons
        latest = self._latest_errors
        now = time.monotonic()
        if not measure and latest is not None and len(latest[0]) == D and now < self._next_errors:
            return latest
        horde, spec, errors = self._errors
        cpu = time.thread_time()
        try:  # a measure never stops the run it measures: what it cannot measure reads NaN
            if horde is not sim.horde or spec is not session.spec:  # the truths: once per set of demons and behaviour
                errors = state_errors(sim.horde, session.spec)
                self._errors = (sim.horde, session.spec, errors)
            cpu = time.thread_time()  # what a measurement costs (the truths above are made once)
            latest = errors.measure(sim.view_state()) if errors is not None else None
        except Exception:
            log.exception("RMSVE and RMSPBE could not be measured; they read NaN for this run")
            self._errors = (sim.horde, session.spec, None)
            latest = None
        if latest is None:
            latest = (np.full(D, np.nan), np.full(D, np.nan))
        self._latest_errors, self._measured_at = latest, sim.total_steps
        self._next_errors = now + max(STATE_ERRORS_INTERVAL, 20 * (time.thread_time() - cpu))
        return latest

    def recorded_to(self) -> int:
        """The step of the latest history row."""
        return self._last_row

    def remap(self, names: list[str]) -> None:
        """The demons changed: the API process remaps its history (`History.remap`) at the next update."""
        self.history = History(names, self.limits.history, self.limits.history_every, self.quantities)
        self._rows.clear()
        self._latest_errors, self._measured_at = None, -1
        self._history = self._history or "remap"

    def new_history(self, names: list[str]) -> None:
        """The run was reset: its history starts afresh."""
        self.remap(names)
        self._history = "new"
        self._last_row = -FOREVER

    # ------------------------------------------------------------------------------------------
    # Publication

    def make_view(self, session: RunSession) -> PublishedView:
        sim = session.sim
        out = sim.readout()
        # The engine freezes a diverged demon itself (the core's one rule); the session reports it in the events
        # when the count of frozen demons changed (reading it is O(D)).
        diverged = int(np.count_nonzero(out.diverged))
        if diverged != self._diverged:
            session.mark_diverged()
            self._diverged = diverged
        self._seq += 1
        world = sim.world_state
        colors = tuple(int(c) for c in world.colors[0]) if isinstance(world, WorldState) else ()
        sensors = None if isinstance(sim, Simulation) else np.array(sim.sensors, copy=True)
        if isinstance(world, WorldState):
            position = (float(world.x[0]), float(world.y[0]))
        else:  # the phase plane's default: the first two sensors
            assert sensors is not None
            position = (float(sensors[0]), float(sensors[min(1, len(sensors) - 1)]))
        return PublishedView(
            status=session.status, message=session.message, hz=session.hz, episode=sim.episode,
            total_steps=sim.total_steps, episode_step=int(world.steps[0]), episode_return=sim.episode_return,
            last_return=sim.last_return, position=position, sensors=sensors, colors=colors, summary=session.summary,
            seq=self._seq, updated_at=time.time(), prediction=np.array(out.prediction, copy=True),
            cumulant=np.array(out.cumulant, copy=True), delta=np.array(out.delta, copy=True),
            rupee=np.array(out.rupee, copy=True), ude=np.array(out.ude, copy=True),
            diverged=np.array(out.diverged, dtype=bool, copy=True), step_size=sim.effective_step_sizes(),
        )  # fmt: skip

    def take_update(self, session: RunSession, force: bool = True) -> Update | None:
        """The update due now (while running: at most every PUBLISH_INTERVAL), or None."""
        began = time.monotonic()
        if not force and began < self._next_publish and session.status == self._status:
            return None
        self._status = session.status
        cpu = time.thread_time()
        view = self.make_view(session)
        # Making a large Horde's view takes time: keep it under about 5 % of the main loop's. The cost is this
        # thread's CPU time, not wall time, so a stall elsewhere cannot stretch the interval; and it is capped,
        # so readers never wait long for a fresh view.
        cost = time.thread_time() - cpu
        spacing = VIEW_ARRAYS * view.prediction.nbytes / VIEW_BYTES_PER_SECOND
        self._next_publish = began + min(MAX_PUBLISH_INTERVAL, max(PUBLISH_INTERVAL, 20 * cost, spacing))
        history, self._history = self._history, ""
        return Update(view=view, rows=self._take_rows(), history=history, **self._take_events(session))  # type: ignore[arg-type]

    def publish(self, session: RunSession, force: bool = True) -> None:
        """Send the current state to the API process (while running: at most every PUBLISH_INTERVAL)."""
        update = self.take_update(session, force)
        if update is not None:
            self.send(update)

    def _take_rows(self) -> Rows | None:
        if not self._rows:
            return None
        steps = np.array([step for step, _ in self._rows], dtype=np.int64)  # [R]
        values = np.stack([row for _, row in self._rows], axis=1)  # [Q, R, D]
        assert values.shape[0] == len(self.quantities)
        self._rows.clear()
        return Rows(steps, values)

    def _take_events(self, session: RunSession) -> dict[str, object]:
        events = session.events.since(self._sent_event, self.limits.events)
        if not events:
            return {}
        skipped = events[0].seq - self._sent_event - 1
        self._sent_event = events[-1].seq
        data = tuple(EventData(e.step, e.episode, e.kind, e.message, e.value) for e in events)
        return {"events": data, "skipped": skipped}

    # ------------------------------------------------------------------------------------------
    # Saves

    def _row(self, session: RunSession) -> RunRecord:
        sim = session.sim
        return RunRecord(id=self.id, name=session.spec.name, status=session.status, message=session.message,
                         hz=session.hz, spec=self._spec_json(session), episode=sim.episode, steps=sim.total_steps,
                         created_at=self.created_at, updated_at=time.time())  # fmt: skip

    def _spec_json(self, session: RunSession) -> str:
        """The spec as the store keeps it, dumped once per spec (a 9,000-demon spec takes 50 ms)."""
        if self._spec is not session.spec:
            self._spec, self._spec_text = session.spec, session.spec.model_dump_json(by_alias=True)
        return self._spec_text

    def save(self, session: RunSession, snapshot: bool) -> Save | None:
        """The run's record (and a snapshot), encoded here, for the API process to write (None: no store)."""
        if snapshot:
            self._last_snapshot = time.monotonic()
        if not self.persist_saves:
            return None
        frozen = (freeze(session.sim, session.spec, session.status, session.hz, session.stop_reference)
                  if snapshot else None)  # fmt: skip
        data = to_bytes(encode_frozen(frozen)) if frozen is not None else None
        summary = session.summary.to_json() if session.summary is not None else None
        return Save(next(self._save_ids), self._row(session), data, summary)

    def save_quietly(self, session: RunSession, snapshot: bool) -> None:
        """A save no caller waits for (a run that finished or failed on its own): sent at once."""
        try:
            save = self.save(session, snapshot)
        except Exception as exc:  # the events say it; the loop goes on
            log.error("run %s could not be saved", self.id, exc_info=exc)
            session.events.add(session.sim.total_steps, session.sim.episode, "error", f"could not save the run: {exc}")
            return
        if save is not None:
            self.send(save)

    def maybe_snapshot(self, session: RunSession) -> None:
        """A periodic snapshot of a running run, frozen here and encoded in the recorder's thread.

        Every `limits.snapshot_every` seconds, or SNAPSHOT_DUTY_RATIO times the last one's encoding and writing
        when that is longer; never while the previous one is still being encoded or written.
        """
        if session.status != "running" or not self.persist_saves:
            return
        with self._pending_lock:
            if self._pending is not None:
                return
        cost = self.snapshot_cost
        interval = max(self.limits.snapshot_every, SNAPSHOT_DUTY_RATIO * (cost.encode_seconds + cost.write_seconds))
        if time.monotonic() - self._last_snapshot < interval:
            return
        self._last_snapshot = time.monotonic()
        began = time.perf_counter()
        frozen = freeze(session.sim, session.spec, session.status, session.hz, session.stop_reference)
        freeze_seconds = time.perf_counter() - began
        save_id = next(self._save_ids)
        record, summary = self._row(session), session.summary.to_json() if session.summary is not None else None
        with self._pending_lock:
            self._pending = save_id

        def encode() -> None:
            try:
                began = time.perf_counter()
                data = to_bytes(encode_frozen(frozen))
                self.snapshot_cost = SnapshotCost(freeze_seconds, time.perf_counter() - began, 0.0, len(data))
                self.send(Save(save_id, record, data, summary))
            except Exception as exc:
                log.error("run %s: a periodic snapshot failed", self.id, exc_info=exc)
                with self._pending_lock:
                    self._pending = None

        self._encoder = threading.Thread(target=encode, name=f"horde-encoder-{self.id}", daemon=True)
        self._encoder.start()

    def saved(self, done: SaveDone) -> None:
        """The API process wrote (or failed to write) a save: the next periodic one may follow."""
        with self._pending_lock:
            if done.save_id == self._pending:
                self._pending = None
                cost = self.snapshot_cost
                self.snapshot_cost = SnapshotCost(cost.freeze_seconds, cost.encode_seconds, done.seconds, cost.bytes)

    def wait_encoded(self, timeout: float = 60.0) -> None:
        """Wait for a periodic snapshot being encoded (before the worker's last save)."""
        if self._encoder is not None:
            self._encoder.join(timeout)
