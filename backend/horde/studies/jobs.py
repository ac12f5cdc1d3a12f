"""Studies run by the server: in a background thread, on the same executors as `horde study`.

The store holds every study and its finished tasks (the CLI's too, when it shares the data directory);
this object adds what only a running study has: its progress, its start time and a cancel switch. One
study runs at a time (Ray spreads its tasks over the cluster already). A study that was running when the
server stopped shows as `interrupted` and can be resumed.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from horde.runs.errors import BusyError, ConflictError, NotFoundError
from horde.runs.store import Store, StudyRecord
from horde.spec import RunSpec
from horde.studies.runner import (
    Executor,
    RayExecutor,
    SummaryCache,
    create_study,
    load_study,
    run_study,
    summarize_study,
)
from horde.studies.spec import StudySpec, study_warnings
from horde.studies.stats import ConfigSummary

log = logging.getLogger(__name__)


@dataclass
class Progress:
    """How far a study running in this process has got."""

    done: int = 0
    total: int = 0
    done_at_start: int = 0
    started: float = field(default_factory=time.monotonic)
    cancel: threading.Event = field(default_factory=threading.Event)

    def seconds_left(self) -> float | None:
        """From the pace of the tasks finished since this start (None until one has)."""
        fresh = self.done - self.done_at_start
        if fresh <= 0:
            return None
        elapsed = time.monotonic() - self.started
        return elapsed / fresh * (self.total - self.done)


def _reads(record: StudyRecord) -> bool:
    """Whether a stored study's spec still reads (one an older version wrote, or changed by hand, may not)."""
    try:
        StudySpec.model_validate_json(record.spec)
    except ValueError as exc:
        log.error("study %s left out: its stored spec cannot be read: %s", record.id, exc)
        return False
    return True


class StudyJobs:
    """The studies of one server.

    Args:
        store: the server's store.
        executor: makes the executor that runs a study's tasks (Ray by default; the tests run in process).
    """

    def __init__(self, store: Store, executor: Callable[[], Executor]) -> None:
        self._store = store
        self._executor = executor
        self._running: dict[str, Progress] = {}
        self._lock = threading.Lock()
        self._threads: list[threading.Thread] = []
        self._summaries: dict[str, tuple[int, list[ConfigSummary]]] = {}  # id -> (tasks done, summaries)
        self._per_config: dict[str, SummaryCache] = {}  # id -> each configuration's summary
        self._warnings: dict[str, list[str]] = {}  # id -> its warnings (its stored spec never changes)

    def start(self, study: StudySpec, base: RunSpec) -> StudyRecord:
        """Validate, record and start a study (SpecError before anything is stored; BusyError while one runs)."""
        with self._lock:
            self._check_idle()
            record, _ = create_study(self._store, study, base)
            self._launch(record.id, record.tasks, 0)
        return self.get(record.id)

    def resume(self, study_id: str) -> StudyRecord:
        """Run a stopped study's unfinished tasks (ConflictError when it runs or has finished)."""
        with self._lock:
            record = self.get(study_id)
            if record.status in ("running", "finished"):
                raise ConflictError(f"study {study_id!r} is {record.status}; nothing to resume")
            self._check_idle()
            self._launch(study_id, record.tasks, self._store.count_study_tasks(study_id))
        return self.get(study_id)

    def _check_idle(self) -> None:
        if self._running:
            raise BusyError("a study is running already (one at a time); wait for it or cancel it")

    def _launch(self, study_id: str, total: int, done: int) -> None:
        """Start the study's thread (the caller holds the lock)."""
        progress = Progress(done=done, total=total, done_at_start=done)
        self._running[study_id] = progress
        self._store.set_study_status(study_id, "running")
        thread = threading.Thread(target=self._run, args=(study_id, progress), name=f"study-{study_id}", daemon=True)
        self._threads.append(thread)
        thread.start()

    def _run(self, study_id: str, progress: Progress) -> None:
        def report(done: int, total: int) -> None:
            progress.done, progress.total = done, total

        try:
            run_study(self._store, study_id, self._executor(), report, progress.cancel.is_set)
        except Exception:  # run_study stored the failure in the study's status and message
            log.exception("study %s failed", study_id)
        finally:
            with self._lock:
                self._running.pop(study_id, None)

    def records(self) -> list[StudyRecord]:
        return [self._current(r) for r in self._store.list_studies() if _reads(r)]

    def get(self, study_id: str) -> StudyRecord:
        record = self._store.get_study(study_id)
        if record is None:
            raise NotFoundError(f"no study {study_id!r}")
        if not _reads(record):
            raise NotFoundError(f"study {study_id!r} is stored but its spec no longer reads (see the server's log)")
        return self._current(record)

    def _current(self, record: StudyRecord) -> StudyRecord:
        if record.status == "running" and record.id not in self._running:
            # left running by a process that stopped (a killed CLI, a restarted server): resumable
            return StudyRecord(**{**record.__dict__, "status": "interrupted"})
        if record.status == "created" and record.id in self._running:
            return StudyRecord(**{**record.__dict__, "status": "running"})
        return record

    def tasks_done(self, study_id: str) -> int:
        return self._store.count_study_tasks(study_id)

    def summaries(self, study_id: str) -> list[ConfigSummary]:
        """The study's results so far (recomputed only when a task has finished since the last call)."""
        self.get(study_id)
        done = self._store.count_study_tasks(study_id)
        with self._lock:
            cached = self._summaries.get(study_id)
        if cached is None or cached[0] != done:
            per_config = self._per_config.setdefault(study_id, {})
            cached = (done, summarize_study(self._store, study_id, per_config))
            with self._lock:
                self._summaries[study_id] = cached
        return cached[1]

    def warnings(self, study_id: str) -> list[str]:
        """What the study's results will not show on their own (`studies.spec.study_warnings`)."""
        if study_id not in self._warnings:
            self._warnings[study_id] = study_warnings(load_study(self._store, study_id)[2])
        return self._warnings[study_id]

    def progress(self, study_id: str) -> Progress | None:
        return self._running.get(study_id)

    def cancel(self, study_id: str) -> StudyRecord:
        """Ask a running study to stop (its finished tasks are kept); a study that is not running is deleted."""
        record = self.get(study_id)
        progress = self._running.get(study_id)
        if progress is not None:
            progress.cancel.set()
            return record
        self._store.delete_study(study_id)
        self._summaries.pop(study_id, None)
        self._per_config.pop(study_id, None)
        self._warnings.pop(study_id, None)
        return record

    def stop(self) -> None:
        for progress in list(self._running.values()):
            progress.cancel.set()
        for thread in self._threads:
            thread.join(timeout=30)
        RayExecutor.shutdown()
