"""The run manager: every live run of the server, created, imported, restored, deleted.

Each run learns in a worker of its own (`LiveRun` here holds its public face; `worker.RunWorker` its loop),
started by the executor (a process of this machine, or a Ray actor). The manager keeps the table of runs,
enforces the limits on their number and size, loads the stored runs at start-up and closes every run at
shutdown. At start-up a run that was running when the server stopped comes back paused; one that was running
when the server died (killed) comes back running from its latest snapshot, at most `limits.snapshot_every`
seconds old; one that had failed (its worker crashed, say) comes back failed and gets no worker: a crash is
never resumed into (reset starts it afresh, in a fresh worker). Saves are written by one thread (`Saver`).
"""

from __future__ import annotations

import contextlib
import logging
import secrets
import threading
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

from horde.core import threads
from horde.runs import messages as m
from horde.runs.collector import keep_out_of_collector
from horde.runs.errors import BusyError, ConflictError, NotFoundError, RunError, SaveError
from horde.runs.executor import ProcessExecutor
from horde.runs.link import Executor, Listener, WorkerGoneError, WorkerLink
from horde.runs.live_run import LiveRun
from horde.runs.readout import Evaluation
from horde.runs.run_setup import Limits, check_limits
from horde.runs.run_view import STATUSES, RunStatus, RunView, Summary
from horde.runs.saver import Saver
from horde.runs.snapshot import Snapshot, check_sizes
from horde.runs.store import RunRecord, Store
from horde.runs.worker import serve_run
from horde.spec import RunSpec

log = logging.getLogger(__name__)

MAX_EVALUATIONS = 2  # Monte-Carlo evaluations running at once
LAUNCHERS = 4  # stored runs started at once at start-up


class RunManager:
    """The runs of one server.

    Args:
        store: where runs are saved and restored from (None: in memory only).
        limits: sizes and timings.
        executor: starts the runs' workers (default: processes of this machine, stopped with the manager).
        hooks: workers honour test crashes (HORDE_TEST_HOOKS; tests only).
    """

    def __init__(self, store: Store | None = None, limits: Limits | None = None,
                 executor: Executor | None = None, hooks: bool = False) -> None:  # fmt: skip
        self.store = store
        self.limits = limits or Limits()
        self.hooks = hooks
        self._owns_executor = executor is None
        self.executor: Executor = executor if executor is not None else ProcessExecutor()
        self._runs: dict[str, LiveRun] = {}
        self._lock = threading.Lock()
        self._making = 0  # runs being made, their slots reserved
        self._evaluations = threading.BoundedSemaphore(MAX_EVALUATIONS)
        self.saver = Saver() if store is not None else None

    def _spawn(self, init: m.RunInit, listener: Listener) -> WorkerLink:
        return self.executor.spawn(serve_run, init, listener)

    def _new_run(self, run_id: str, spec: RunSpec | None, created_at: float | None = None) -> LiveRun:
        run = LiveRun(run_id, spec, self.limits, self._spawn, self.store, self.saver, created_at, self.hooks)
        run.on_status = self._share_cores
        return run

    def _share_cores(self) -> None:
        """Give each learning run's worker its share of this machine's cores (a run alone takes them all, two take
        one each on two cores), as the runs of one process shared them (`core.threads.share`). Ray's actors have
        the CPUs they asked the cluster for."""
        if self.executor.kind != "process":
            return
        with self._lock:
            runs = list(self._runs.values())
        learning = [run for run in runs if run.view.status == "running"]
        share = max(1, threads.cores() // max(1, len(learning)))
        for run in learning:
            link = run.link
            if link is not None and link.alive and run.threads != share:
                run.threads = share
                with contextlib.suppress(WorkerGoneError):
                    link.send(m.SetThreads(share))

    # ------------------------------------------------------------------------------------------
    # Life cycle

    def start(self) -> None:
        """Load the stored runs and start their workers (a few at once); a run whose spec no longer reads is left
        in the store, out of the table, and logged (the store is untrusted too)."""
        if self.store is None:
            return
        records = self.store.list_runs()
        with ThreadPoolExecutor(LAUNCHERS, thread_name_prefix="horde-revive") as pool:
            for run in pool.map(self._revive_or_skip, records):
                if run is None:
                    continue
                with self._lock:
                    self._runs[run.id] = run
        keep_out_of_collector()

    def _revive_or_skip(self, record: RunRecord) -> LiveRun | None:
        try:
            return self._revive(record)
        except Exception as exc:  # its spec no longer reads (an older version's, or changed by hand)
            log.error("run %s left out: its stored spec cannot be read: %s", record.id, exc)
            return None

    def stop(self) -> None:
        """Close every run (running ones are saved as paused), a few at once; a run that cannot is logged."""
        with self._lock:
            runs = list(self._runs.values())
            self._runs.clear()

        def close(run: LiveRun) -> None:
            try:
                run.close()
            except RunError as exc:
                log.error("run %s: %s", run.id, exc)

        with ThreadPoolExecutor(LAUNCHERS * 2, thread_name_prefix="horde-close") as pool:
            list(pool.map(close, runs))
        if self.saver is not None:
            self.saver.stop()
        if self._owns_executor:
            self.executor.stop()

    def _revive(self, record: RunRecord) -> LiveRun:
        """A stored run, back from its latest snapshot in a new worker; a run that had failed, or cannot be
        restored, comes back failed without one."""
        assert self.store is not None
        summary_text = self.store.load_summary(record.id)
        summary = Summary.from_json(summary_text) if summary_text else None
        status: RunStatus = next((s for s in STATUSES if s == record.status), "failed")
        spec = RunSpec.model_validate_json(record.spec)
        run = self._new_run(record.id, spec, record.created_at)
        if status == "failed":
            run.show_stored(record, summary)
            return run
        data = self.store.load_snapshot(record.id)
        if data is None and status == "running":  # it died before its first snapshot: it runs again from step 0
            init = m.RunInit(record.id, self.limits, spec=spec, status="running", hz=record.hz,
                             created_at=record.created_at, persist=True, hooks=self.hooks, resumed=True)  # fmt: skip
        elif data is None:  # a run saved as it was made (its spec and seed are its state)
            message = record.message if status == "created" else "no snapshot was saved; it starts afresh"
            init = m.RunInit(record.id, self.limits, spec=spec, message=message, created_at=record.created_at,
                             persist=True, hooks=self.hooks)  # fmt: skip
        else:
            init = m.RunInit(record.id, self.limits, stored=data, status=status, hz=record.hz, message=record.message,
                             created_at=record.created_at, summary=summary, persist=True, hooks=self.hooks,
                             resumed=status == "running")  # fmt: skip
        try:
            run.launch(init)
        except Exception as exc:
            log.error("run %s could not be restored", record.id, exc_info=exc)
            failed = RunRecord(**{**record.__dict__, "status": "failed", "message": f"could not be restored: {exc}",
                                  "updated_at": time.time()})  # fmt: skip
            run.show_stored(failed, summary)
            try:
                self.store.save_run(failed)
            except Exception as error:
                log.error("run %s: could not save that it failed", record.id, exc_info=error)
        return run

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
        """A new run of the spec (seeded as trial 0 of its protocol), built in its worker, started if asked.

        Raises:
            SpecError: the spec is larger than the limits allow, or cannot run.
            ConflictError: there are as many runs as the limits allow.
            SaveError: the store refused the run; it was not made.
        """
        check_limits(spec, self.limits)
        run = self._add(lambda run_id: (
            self._new_run(run_id, spec),
            m.RunInit(run_id, self.limits, spec=spec, hz=hz, created_at=time.time(), persist=self.store is not None,
                      first_save=True, hooks=self.hooks),
        ))  # fmt: skip
        return run.start() if start else run.view

    def create_from(self, data: dict[str, Any], loc: tuple[str | int, ...], hz: float | None = None,
                    start: bool = False) -> RunView:  # fmt: skip
        """A new run of a spec given as data, validated, checked against the limits and built in its worker (a
        Horde of thousands of demons is never validated or compiled in this process).

        Raises:
            SpecError: the data does not validate (its problems located under `loc`), or is larger than the
                limits allow, or cannot run.
            ConflictError: there are as many runs as the limits allow.
            SaveError: the store refused the run; it was not made.
        """
        run = self._add(lambda run_id: (
            self._new_run(run_id, None),
            m.RunInit(run_id, self.limits, data=data, loc=loc, hz=hz, created_at=time.time(),
                      persist=self.store is not None, first_save=True, hooks=self.hooks),
        ))  # fmt: skip
        return run.start() if start else run.view

    def import_snapshot(self, snapshot: Snapshot) -> RunView:
        """A new run that continues exactly where the snapshot's run stood (paused, or finished)."""
        check_limits(snapshot.spec, self.limits)
        check_sizes(snapshot)
        status: RunStatus = snapshot.status
        if status != "finished":
            status = "paused" if snapshot.total_steps > 0 else "created"
        run = self._add(lambda run_id: (
            self._new_run(run_id, snapshot.spec),
            m.RunInit(run_id, self.limits, snapshot=snapshot, status=status, hz=snapshot.hz,
                      message="imported from a snapshot", created_at=time.time(), persist=self.store is not None,
                      first_save=True, hooks=self.hooks),
        ))  # fmt: skip
        return run.view

    def _add(self, make: Callable[[str], tuple[LiveRun, m.RunInit]]) -> LiveRun:
        """Make a run in its worker (outside the lock: a large Horde takes a while, and readers of the table must
        not wait for it) in a slot reserved under the lock; its first save written, list it.

        Raises:
            ConflictError: there are as many runs as the limits allow.
            SaveError: the store refused the run; it was not made (a restart would not know it).
        """
        with self._lock:
            if len(self._runs) + self._making >= self.limits.max_runs:
                raise ConflictError(f"this server holds at most {self.limits.max_runs} runs; delete one first")
            self._making += 1
        try:
            run, init = make(secrets.token_hex(6))
            try:
                run.launch(init)
            except SaveError as exc:
                raise SaveError(f"the run was not created: {exc.__cause__ or exc}") from exc
            keep_out_of_collector()
            with self._lock:
                self._runs[run.id] = run
        finally:
            with self._lock:
                self._making -= 1
        return run

    def delete(self, run_id: str) -> None:
        """End a run's worker and forget the run, in memory and in the store (a worker that does not end in time
        is killed).

        Raises:
            NotFoundError: no such run.
        """
        with self._lock:
            run = self._runs.pop(run_id, None)
        if run is None:
            raise NotFoundError(f"no run {run_id!r}")
        with contextlib.suppress(SaveError):
            run.close(save=False)  # it is being deleted: nothing of it is saved
        if self.store is not None:
            self.store.delete_run(run_id)

    # ------------------------------------------------------------------------------------------
    # Evaluation (in the run's worker, on a frozen copy of its weights)

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
        slot is held no longer than someone waits, and never past the budget).

        Raises:
            BusyError: MAX_EVALUATIONS evaluations are already running.
            SpecError: the rollouts did not finish in time (naming `episodes`).
            StoppedError: the client went away first.
        """
        run = self.get(run_id)
        if not self._evaluations.acquire(blocking=False):
            raise BusyError(f"{MAX_EVALUATIONS} evaluations are running already; try again when they are done")
        try:
            command = m.Evaluate(demon, start, episodes, cap, seed, self.limits.evaluation_seconds)
            result: Evaluation = run.evaluate(command, abandoned)
            return result
        finally:
            self._evaluations.release()
