"""A run's recorder: its history rows, the views it publishes to readers, and its saves to the store.

The learner thread calls the recorder between two chunks of steps (never while learning), with the
session whose state it records. Publishing makes an immutable `RunView` (readers never touch the
source); saving freezes the state in the learner thread and hands encoding and writing to the saver's
thread when there is one. A save that a command waits for raises `SaveError` when it fails (the caller
hears it, and the run's message says it); a periodic one tells its failure in the run's events.
"""

from __future__ import annotations

import contextlib
import logging
import time
from concurrent.futures import Future
from dataclasses import dataclass
from typing import Any

import numpy as np

from horde.core.engine.layout import FOREVER
from horde.core.simulation import Simulation
from horde.core.world import WorldState
from horde.runs.errors import SaveError
from horde.runs.history import History
from horde.runs.run_setup import Limits
from horde.runs.run_view import RunView
from horde.runs.saver import Saver
from horde.runs.session import RunSession
from horde.runs.snapshot import encode_frozen, freeze, to_bytes
from horde.runs.store import RunRecord, Store

# A periodic snapshot waits this many times the last one's encoding and writing: encoding holds the GIL, and at
# three times (a third of the time) a live nexting run with the dashboard open learned 16 steps/s, not 30.
SNAPSHOT_DUTY_RATIO = 10

log = logging.getLogger(__name__)

PUBLISH_INTERVAL = 1.0 / 60.0  # while running, views are published at most this often
MAX_PUBLISH_INTERVAL = 0.5  # ... and at least this often, however long a view takes to make
COMMAND_TIMEOUT = 600.0  # a waited save waits this long for the writer at most
NOT_SAVED = "; not saved: "  # what a run's message adds when its latest waited save failed


@dataclass(frozen=True)
class SnapshotCost:
    """What the latest snapshot cost: freezing it in the learner thread, encoding and writing it after."""

    freeze_seconds: float = 0.0
    encode_seconds: float = 0.0
    write_seconds: float = 0.0
    bytes: int = 0


class Recorder:
    """History, publication and persistence of one run.

    Args:
        run_id: the run's id.
        limits: the server's limits (history size, intervals).
        store: where the run saves itself (None: nowhere).
        saver: the writer thread that saves are handed to (None: written in the learner thread).
        created_at: the run's creation time.
        names: the demons, for the history.
    """

    def __init__(self, run_id: str, limits: Limits, store: Store | None, saver: Saver | None, created_at: float,
                 names: list[str]) -> None:  # fmt: skip
        self.id = run_id
        self.limits = limits
        self.store = store
        self.saver = saver
        self.created_at = created_at
        self.history = History(names, limits.history, limits.history_every)
        self.snapshot_cost = SnapshotCost()
        self.view: RunView | None = None
        self._pending_save: Future[Any] | None = None  # the periodic snapshot being written
        self._seq = 0
        self._last_row = -FOREVER  # no row yet
        self._next_row = 0.0
        self._next_publish = 0.0
        self._last_snapshot = time.monotonic()

    # ------------------------------------------------------------------------------------------
    # History

    def maybe_record(self, session: RunSession) -> None:
        """A row when `history.every` steps and `limits.history_interval` seconds have passed since the last:
        every step of a run paced by hz (up to 1/interval steps per second), a sample at full speed."""
        if session.sim.total_steps - self._last_row >= self.history.every and time.monotonic() >= self._next_row:
            self.record(session)

    def record(self, session: RunSession) -> None:
        sim = session.sim
        out = sim.readout()  # O(D): no weights are copied
        prediction = np.where(out.diverged, np.nan, out.prediction)  # [D] a frozen demon's 0s are no answer: null
        self.history.record(sim.total_steps, prediction, out.cumulant, out.delta, out.rupee, out.ude)
        self._last_row = sim.total_steps
        self._next_row = time.monotonic() + self.limits.history_interval

    def recorded_to(self) -> int:
        """The step of the latest history row."""
        return self._last_row

    def remap(self, names: list[str]) -> None:
        self.history = self.history.remap(names)

    def new_history(self, names: list[str]) -> None:
        self.history = History(names, self.limits.history, self.limits.history_every)
        self._last_row = -FOREVER

    # ------------------------------------------------------------------------------------------
    # Publication

    def make_view(self, session: RunSession) -> RunView:
        session.mark_diverged()
        sim = session.sim
        self._seq += 1
        world = sim.world_state
        if isinstance(world, WorldState):
            world = WorldState(*(np.array(a, copy=True) for a in world))
        out = sim.readout()
        return RunView(
            id=self.id, status=session.status, message=session.message, hz=session.hz, spec=session.spec,
            horde=sim.horde,
            horde_state=sim.view_state(),  # a copy of what readers need: the learner never changes it
            rupee=out.rupee, ude=out.ude, world_state=world, episode=sim.episode, total_steps=sim.total_steps,
            episode_return=sim.episode_return, last_return=sim.last_return, created_at=self.created_at,
            updated_at=time.time(), summary=session.summary, seq=self._seq, step_size=sim.effective_step_sizes(),
            sensors=None if isinstance(sim, Simulation) else sim.sensors,
        )  # fmt: skip

    def publish(self, session: RunSession, force: bool = True) -> RunView:
        """Make the current state visible to readers (while running: at most every PUBLISH_INTERVAL)."""
        began = time.monotonic()
        if force or self.view is None or began >= self._next_publish or session.status != self.view.status:
            cpu = time.thread_time()
            self.view = self.make_view(session)
            # Copying a large Horde takes time: keep it under about 5 % of the learner thread's. The cost is
            # this thread's CPU time, not wall time, so a stall elsewhere (the event loop holding the GIL)
            # cannot stretch the interval; and it is capped, so readers never wait long for a fresh view.
            cost = time.thread_time() - cpu
            self._next_publish = began + min(MAX_PUBLISH_INTERVAL, max(PUBLISH_INTERVAL, 20 * cost))
        return self.view

    def commit(self, session: RunSession, snapshot: bool) -> RunView:
        """Save the state a command left (waiting for the write) and publish it.

        Raises:
            SaveError: the write failed; the state is published all the same, its message saying so.
        """
        try:
            self.persist(session, snapshot)
        finally:
            view = self.publish(session)
        return view

    # ------------------------------------------------------------------------------------------
    # Persistence

    def maybe_snapshot(self, session: RunSession) -> None:
        """A periodic snapshot of a running run, handed to the writer thread.

        Every `limits.snapshot_every` seconds, or SNAPSHOT_DUTY_RATIO times the last write's time when that
        is longer (a large Horde's writes then keep the writer, which holds the GIL while it encodes, busy a
        tenth of the time at most); never while the previous one is still being written.
        """
        pending = self._pending_save
        if session.status != "running" or (pending is not None and not pending.done()):
            return
        if pending is not None and pending.exception() is None:
            self._saved(session)
        cost = self.snapshot_cost
        interval = max(self.limits.snapshot_every, SNAPSHOT_DUTY_RATIO * (cost.encode_seconds + cost.write_seconds))
        if time.monotonic() - self._last_snapshot >= interval:
            self.persist(session, snapshot=True, wait=False)

    def save_quietly(self, session: RunSession, snapshot: bool) -> None:
        """Save where no caller waits for the answer: a failure is told in the message and the events."""
        with contextlib.suppress(SaveError):
            self.persist(session, snapshot)

    def _saved(self, session: RunSession) -> None:
        """A save worked: what the message said of an earlier failure no longer holds."""
        session.message = session.message.split(NOT_SAVED)[0]

    def _row(self, session: RunSession) -> RunRecord:
        """The run's row in the store, as it stands now (saved, so without what the message said of a failure)."""
        sim = session.sim
        message = session.message.split(NOT_SAVED)[0]
        return RunRecord(id=self.id, name=session.spec.name, status=session.status, message=message,
                         hz=session.hz, spec=session.spec.model_dump_json(by_alias=True), episode=sim.episode,
                         steps=sim.total_steps, created_at=self.created_at, updated_at=time.time())  # fmt: skip

    def persist(self, session: RunSession, snapshot: bool, wait: bool = True) -> None:
        """Save the run's record (and a snapshot) in one transaction.

        The state is frozen here, in the learner thread; encoding and writing happen in the saver's
        thread when there is one. With `wait` the call returns once the write is done, and a failed
        write raises; without it (the periodic snapshots) a failure is told in the run's events.

        Raises:
            SaveError: with `wait`, the write failed or did not finish within COMMAND_TIMEOUT; the run's
                message and events say so too.
        """
        if snapshot:
            self._last_snapshot = time.monotonic()
        if self.store is None:
            return
        store = self.store
        if wait:  # this save's outcome replaces what the message said of the last one
            self._saved(session)
        try:
            began = time.perf_counter()
            record = self._row(session)
            frozen = (freeze(session.sim, session.spec, session.status, session.hz, session.stop_reference)
                      if snapshot else None)  # fmt: skip
            summary = session.summary.to_json() if session.summary is not None else None
            freeze_seconds = time.perf_counter() - began
        except Exception as exc:
            self._save_failed(session, exc, wait)
            return

        def write() -> None:
            began = time.perf_counter()
            data = to_bytes(encode_frozen(frozen)) if frozen is not None else None
            encoded = time.perf_counter()
            store.save_run(record, data, summary)
            if data is not None:
                self.snapshot_cost = SnapshotCost(freeze_seconds, encoded - began, time.perf_counter() - encoded,
                                                  len(data))  # fmt: skip

        self._write(session, write, wait)

    def _write(self, session: RunSession, write: Any, wait: bool) -> None:
        if self.saver is None:
            try:
                write()
            except Exception as exc:
                self._save_failed(session, exc, wait)
            else:
                self._saved(session)
            return
        future = self.saver.submit(write)
        if not wait:
            self._pending_save = future
            future.add_done_callback(lambda done: self._background_save_done(session, done))
            return
        try:
            future.result(COMMAND_TIMEOUT)
        except TimeoutError:
            self._save_failed(session, TimeoutError(f"the write did not finish within {COMMAND_TIMEOUT:g} s"), wait)
        except Exception as exc:
            self._save_failed(session, exc, wait)

    def _background_save_done(self, session: RunSession, future: Future[Any]) -> None:
        """A periodic snapshot's write ended (in the saver's thread): a failure goes to the events."""
        exc = future.exception()
        if isinstance(exc, Exception):
            self._save_failed(session, exc, wait=False)

    def _save_failed(self, session: RunSession, exc: Exception, wait: bool) -> None:
        """A save failed: the events say so; a waited one (in the learner thread) also the message, and raises.

        Raises:
            SaveError: when `wait`.
        """
        log.error("could not save run %s", self.id, exc_info=exc)
        session.events.add(session.sim.total_steps, session.sim.episode, "error", f"could not save the run: {exc}")
        if wait:
            said = session.message or session.status
            session.message = f"{said}{NOT_SAVED}{exc}"
            raise SaveError(f"run {self.id!r}: {said}, but it could not be saved: {exc}") from exc
