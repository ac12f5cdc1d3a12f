"""Studies run by the server: each in a driver process of its own (`driver.py`), on the executors of `horde study`.

The store holds every study and its finished tasks (the CLI's too, when it shares the data directory);
this object adds what only a running study has: its driver, its progress, its start time. One study runs at
a time (Ray spreads its tasks over the cluster already). On Ray, the study joins the cluster given
(`ray_address`) or the server's own one-node Ray (`LocalRay`, started with the first study, and again after it
died). A driver that dies (Ray went away under it, or it was killed) fails its study, saying why; it resumes
once Ray is back. A study that was running when the server stopped shows as `interrupted` and can be resumed.
"""

from __future__ import annotations

import contextlib
import logging
import threading
import time
from dataclasses import dataclass, field
from typing import Literal

from horde.runs.errors import BusyError, ConflictError, NotFoundError
from horde.runs.executor import ProcessExecutor
from horde.runs.link import WorkerGoneError, WorkerLink, stall_words
from horde.runs.messages import Cancel, Command, Finished, FromWorker, Reply, StudyInit
from horde.runs.messages import Progress as ProgressMessage
from horde.runs.store import Store, StudyRecord
from horde.spec import RunSpec
from horde.studies.driver import serve_study
from horde.studies.local_ray import LocalRay
from horde.studies.runner import SummaryCache, create_study, load_study, summarize_study
from horde.studies.spec import StudySpec, study_warnings
from horde.studies.stats import ConfigSummary

log = logging.getLogger(__name__)

ENDING_WAIT = 10.0  # seconds a delete waits for a study that has stored its end to leave the running ones


@dataclass
class Progress:
    """How far a study running in this process has got."""

    done: int = 0
    total: int = 0
    done_at_start: int = 0
    started: float = field(default_factory=time.monotonic)
    cancel: threading.Event = field(default_factory=threading.Event)
    ended: threading.Event = field(default_factory=threading.Event)
    link: WorkerLink | None = None

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
        workers: starts the studies' driver processes.
        kind: "ray" (on the cluster at `address`, else on the server's own Ray) or "local" (one task after
            the other, in the driver).
        address: a Ray cluster to join.
        cpus: CPUs of the server's own Ray (default: every core).
    """

    def __init__(self, store: Store, workers: ProcessExecutor, kind: Literal["ray", "local"] = "ray",
                 address: str | None = None, cpus: int | None = None) -> None:  # fmt: skip
        self._store = store
        self._workers = workers
        self._kind = kind
        self._address = address
        self.local_ray = LocalRay(cpus, store.path.parent / "ray") if kind == "ray" and address is None else None
        self._running: dict[str, Progress] = {}
        self._lock = threading.Lock()
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
        """Start the study's driver (the caller holds the lock); a Ray that cannot start fails the study."""
        progress = Progress(done=done, total=total, done_at_start=done)
        self._store.set_study_status(study_id, "running")
        try:
            init = self._init(study_id)
            self._running[study_id] = progress
            progress.link = self._workers.spawn(serve_study, init, _StudyDriver(self, study_id, progress))
        except Exception as exc:
            self._running.pop(study_id, None)
            self._store.set_study_status(study_id, "failed", f"its driver did not start: {exc}")
            raise ConflictError(f"study {study_id!r} could not start: {exc}") from None

    def _init(self, study_id: str) -> StudyInit:
        data = str(self._store.path.parent)
        if self._kind == "local":
            return StudyInit(data, study_id, "local")
        if self.local_ray is not None:
            return StudyInit(data, study_id, "ray", self.local_ray.address(), env=self.local_ray.env())
        return StudyInit(data, study_id, "ray", self._address)

    def _ended(self, study_id: str, why: str | None) -> None:
        """The study's driver ended; `why` it failed, if it could not store that itself (the store then says it).
        The study leaves the running ones only once the store holds how it ended (`_current` relies on that)."""
        with self._lock:
            progress = self._running.get(study_id)
        if why is not None:
            record = self._store.get_study(study_id)
            if record is not None and record.status == "running":
                done = progress.done if progress is not None else self._store.count_study_tasks(study_id)
                total = progress.total if progress is not None else record.tasks
                on_ray = " (Ray may have gone away under it)" if self._kind == "ray" else ""
                self._store.set_study_status(study_id, "failed", f"its driver ended ({why}){on_ray} after {done} of "
                                             f"{total} tasks; its finished tasks are kept: resume it")  # fmt: skip
        with self._lock:
            self._running.pop(study_id, None)
        if progress is not None:
            progress.ended.set()

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
            # Read again: its driver may have stored how it ended since `record` was read (and then left the
            # running ones). Still running: left so by a process that stopped (a killed CLI, a restarted
            # server), resumable.
            again = self._store.get_study(record.id)
            if again is not None and again.status != "running":
                return again
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
        stored = self._store.get_study(study_id)
        if progress is not None and stored is not None and stored.status not in ("created", "running"):
            # Its driver has stored how it ended and is about to leave the running ones (`_ended`): it is not
            # running any more, so it is deleted once it has left.
            progress.ended.wait(ENDING_WAIT)
            progress = self._running.get(study_id)
        if progress is not None:
            progress.cancel.set()
            if progress.link is not None:
                with contextlib.suppress(WorkerGoneError):
                    progress.link.send(Cancel(0))
            return record
        self._store.delete_study(study_id)
        self._summaries.pop(study_id, None)
        self._per_config.pop(study_id, None)
        self._warnings.pop(study_id, None)
        return record

    def stop(self) -> None:
        """Cancel the running study, end its driver, and stop the server's own Ray."""
        for study_id in list(self._running):
            self.cancel(study_id)
        for progress in list(self._running.values()):
            progress.ended.wait(30)
            if progress.link is not None:
                progress.link.stop()
        if self.local_ray is not None:
            self.local_ray.stop()


class _StudyDriver:
    """What a study's driver says (`executor.Listener`)."""

    def __init__(self, jobs: StudyJobs, study_id: str, progress: Progress) -> None:
        self.jobs, self.study_id, self.progress = jobs, study_id, progress

    def on_message(self, message: FromWorker) -> None:
        if isinstance(message, ProgressMessage):
            self.progress.done, self.progress.total = message.done, message.total
        elif isinstance(message, Finished):
            if self.progress.link is not None:
                self.progress.link.stopping = True
            # A failure the driver could not store itself (its store refused the write, say) is stored here.
            self.jobs._ended(self.study_id, message.failure.message if message.failure is not None else None)

    def on_reply(self, command: Command | None, reply: Reply) -> None:
        pass

    def on_exit(self, reason: str) -> None:
        self.jobs._ended(self.study_id, reason)

    def on_stall(self, seconds: float, doing: str) -> None:
        if seconds > 0:
            log.error("study %s: %s", self.study_id, stall_words(seconds, doing, "its driver"))
