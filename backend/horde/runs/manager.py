"""The run manager: every live run of the server, created, imported, restored, deleted.

Each run has its own learner thread (`LiveRun`). The manager keeps the table of runs, enforces the
limits on their number and size, loads the stored runs at start-up (a run that was running when the
server stopped comes back paused; one that was running when the process died, say killed, comes back
running from its latest snapshot, at most `limits.snapshot_every` seconds old) and closes every run at
shutdown. Periodic snapshots are written by one background thread (`Saver`).
"""

from __future__ import annotations

import logging
import secrets
import threading
import time
from collections.abc import Callable

from horde.core.evaluate import StoppedError
from horde.runs.collector import keep_out_of_collector
from horde.runs.errors import BusyError, ConflictError, NotFoundError, RunError, SaveError, SpecError
from horde.runs.live_run import LiveRun
from horde.runs.readout import Evaluation, evaluate
from horde.runs.run_setup import Limits, check_limits, new_simulation
from horde.runs.run_view import STATUSES, RunStatus, RunView, Summary
from horde.runs.saver import Saver
from horde.runs.snapshot import Snapshot, from_bytes, restore
from horde.runs.store import RunRecord, Store
from horde.spec import RunSpec

log = logging.getLogger(__name__)

MAX_EVALUATIONS = 2  # Monte-Carlo evaluations running at once


class RunManager:
    """The runs of one server.

    Args:
        store: where runs are saved and restored from (None: in memory only).
        limits: sizes and timings.
    """

    def __init__(self, store: Store | None = None, limits: Limits | None = None) -> None:
        self.store = store
        self.limits = limits or Limits()
        self._runs: dict[str, LiveRun] = {}
        self._lock = threading.Lock()
        self._making = 0  # runs being made, their slots reserved
        self._evaluations = threading.BoundedSemaphore(MAX_EVALUATIONS)
        self.saver = Saver() if store is not None else None

    # ------------------------------------------------------------------------------------------
    # Life cycle

    def start(self) -> None:
        """Load the stored runs and start their learner threads; a run whose spec no longer reads is left in the
        store, out of the table, and logged (the store is untrusted too)."""
        if self.store is None:
            return
        for record in self.store.list_runs():
            try:
                run = self._revive(record)
            except Exception as exc:  # its spec no longer reads (an older version's, or changed by hand)
                log.error("run %s left out: its stored spec cannot be read: %s", record.id, exc)
                continue
            with self._lock:
                self._runs[run.id] = run
            run.start_thread()

    def stop(self) -> None:
        """Close every run (running ones are saved as paused); a run that cannot stop or save is logged."""
        with self._lock:
            runs = list(self._runs.values())
            self._runs.clear()
        for run in runs:
            try:
                run.close()
            except RunError as exc:
                log.error("run %s: %s", run.id, exc)
        if self.saver is not None:
            self.saver.stop()

    def _revive(self, record: RunRecord) -> LiveRun:
        """A stored run, back from its latest snapshot; a run that cannot be restored comes back failed."""
        assert self.store is not None
        summary_text = self.store.load_summary(record.id)
        summary = Summary.from_json(summary_text) if summary_text else None
        status: RunStatus = next((s for s in STATUSES if s == record.status), "failed")
        try:
            data = self.store.load_snapshot(record.id)
            if data is None:
                sim = new_simulation(RunSpec.model_validate_json(record.spec))
                message = record.message if status == "created" else "no snapshot was saved; it starts afresh"
                return LiveRun(
                    record.id,
                    sim,
                    self.limits,
                    self.store,
                    message=message,
                    created_at=record.created_at,
                    saver=self.saver,
                )
            restored = restore(from_bytes(data))
        except Exception as exc:
            log.error("run %s could not be restored", record.id, exc_info=exc)
            sim = new_simulation(RunSpec.model_validate_json(record.spec))
            return LiveRun(
                record.id,
                sim,
                self.limits,
                self.store,
                status="failed",
                message=f"could not be restored: {exc}",
                created_at=record.created_at,
                saver=self.saver,
            )
        message = record.message
        if status == "running":  # the process died while it ran: it goes on from its latest snapshot
            message = f"running again from step {restored.sim.total_steps}, its latest snapshot, after a restart"
        return LiveRun(
            record.id,
            restored.sim,
            self.limits,
            self.store,
            status=status,
            hz=record.hz,
            message=message,
            created_at=record.created_at,
            summary=summary,
            stop_reference=restored.stop_reference,
            saver=self.saver,
        )

    # ------------------------------------------------------------------------------------------
    # The table of runs

    def list(self) -> list[RunView]:
        with self._lock:
            runs = list(self._runs.values())
        return [run.view for run in runs]

    def get(self, run_id: str) -> LiveRun:
        with self._lock:
            run = self._runs.get(run_id)
        if run is None:
            raise NotFoundError(f"no run {run_id!r}")
        return run

    def create(self, spec: RunSpec, hz: float | None = None, start: bool = False) -> RunView:
        """A new run of the spec (seeded as trial 0 of its protocol), started if asked.

        Raises:
            SpecError: the spec is larger than the limits allow, or cannot run.
            ConflictError: there are as many runs as the limits allow.
        """
        check_limits(spec, self.limits)
        sim = new_simulation(spec)
        run = self._add(lambda run_id: LiveRun(run_id, sim, self.limits, self.store, hz=hz, saver=self.saver))
        return run.start() if start else run.view

    def import_snapshot(self, snapshot: Snapshot) -> RunView:
        """A new run that continues exactly where the snapshot's run stood (paused, or finished)."""
        check_limits(snapshot.spec, self.limits)
        restored = restore(snapshot)
        status = restored.status
        if status != "finished":
            status = "paused" if restored.sim.total_steps > 0 else "created"
        run = self._add(
            lambda run_id: LiveRun(
                run_id,
                restored.sim,
                self.limits,
                self.store,
                status=status,
                hz=restored.hz,
                message="imported from a snapshot",
                stop_reference=restored.stop_reference,
                saver=self.saver,
            )
        )
        return run.view

    def _add(self, make: Callable[[str], LiveRun]) -> LiveRun:
        """Make a run (outside the lock: a large Horde takes a while, and readers of the table must not
        wait for it) in a slot reserved under the lock, save it, then list it and start its thread.

        Raises:
            ConflictError: there are as many runs as the limits allow.
            SaveError: the store refused the run; it was not made (a restart would not know it).
        """
        with self._lock:
            if len(self._runs) + self._making >= self.limits.max_runs:
                raise ConflictError(f"this server holds at most {self.limits.max_runs} runs; delete one first")
            self._making += 1
        try:
            run = make(secrets.token_hex(6))
            keep_out_of_collector()
            try:
                run.save()
            except SaveError as exc:
                raise SaveError(f"the run was not created: {exc.__cause__ or exc}") from exc
            with self._lock:
                self._runs[run.id] = run
        finally:
            with self._lock:
                self._making -= 1
        run.start_thread()
        return run

    def delete(self, run_id: str) -> None:
        """Stop a run's thread and forget it, in memory and in the store.

        Raises:
            NotFoundError: no such run.
            BusyError: its learner thread did not stop in time; the run stays listed.
        """
        with self._lock:
            run = self._runs.pop(run_id, None)
        if run is None:
            raise NotFoundError(f"no run {run_id!r}")
        try:
            run.close()
        except SaveError:
            pass  # its last save failed: it is being deleted anyway
        except BusyError:  # still busy: it stays listed (and stops when its work ends); deleting again succeeds
            with self._lock:
                self._runs.setdefault(run_id, run)
            raise
        if self.store is not None:
            self.store.delete_run(run_id)

    # ------------------------------------------------------------------------------------------
    # Evaluation (outside the learner thread, on a frozen view)

    def evaluate(
        self,
        run_id: str,
        demon: str,
        start: tuple[float, float] | None,
        episodes: int,
        cap: int,
        seed: int | None,
        abandoned: Callable[[], bool] = lambda: False,
    ) -> Evaluation:
        """Monte-Carlo truth of a demon's question from `start` (`readout.evaluate`), beside its prediction there,
        given up after `limits.evaluation_seconds`, or as soon as `abandoned()` says its client has gone (so a
        thread and a slot are held no longer than someone waits, and never past the budget).

        Raises:
            BusyError: MAX_EVALUATIONS evaluations are already running.
            SpecError: the rollouts did not finish in time (naming `episodes`).
            StoppedError: the client went away first.
        """
        view = self.get(run_id).view
        if not self._evaluations.acquire(blocking=False):
            raise BusyError(f"{MAX_EVALUATIONS} evaluations are running already; try again when they are done")
        budget = self.limits.evaluation_seconds
        over_time = _time_budget(budget)
        try:
            return evaluate(view, demon, start, episodes, cap, seed, stop=lambda: abandoned() or over_time())
        except StoppedError as exc:
            if abandoned():
                raise
            raise SpecError.at(("body", "episodes"), f"the rollouts did not finish within {budget:g} s ({exc}): "
                               "ask for fewer episodes or a smaller cap") from None  # fmt: skip
        finally:
            self._evaluations.release()


def _time_budget(seconds: float) -> Callable[[], bool]:
    """A `stop` that says so once `seconds` have passed since it was first asked: after the first chunk of
    rollouts, whose time may be that of compiling them (once per process)."""
    deadline: list[float] = []

    def stop() -> bool:
        if not deadline:
            deadline.append(time.monotonic() + seconds)
        return time.monotonic() > deadline[0]

    return stop
