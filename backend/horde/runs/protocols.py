"""Protocol jobs: a scenario's whole protocol (trials x episodes, Monte-Carlo truth, test runs), run in
the background for the server, as `horde run` runs it on the command line.

Each job learns in a worker of its own (`job_workers.serve_protocol`), which tells its progress as it goes;
a worker that dies fails its job, saying why. One job runs at a time (the protocol uses a whole core); the
last `KEEP` jobs are kept. With a store,
every job is saved there as it starts, with its progress at most every `PROGRESS_SECONDS`, and with its
result when it ends: after a restart the finished jobs are back as they were, and a job that was
running when the server stopped (or died) is back as `interrupted`, with how far it got.
"""

from __future__ import annotations

import contextlib
import json
import logging
import secrets
import threading
import time
from dataclasses import dataclass, field
from typing import Any, Literal

from horde.core.experiment import DemonResult, ProtocolResult
from horde.runs.errors import BusyError, NotFoundError
from horde.runs.executor import ProcessExecutor
from horde.runs.job_workers import serve_protocol
from horde.runs.link import Executor, WorkerGoneError, WorkerLink, stall_words
from horde.runs.messages import Cancel, Command, Finished, FromWorker, Progress, ProtocolInit, Reply
from horde.runs.store import JobRecord, Store
from horde.spec import Counts, RunSpec

log = logging.getLogger(__name__)

JobStatus = Literal["running", "finished", "failed", "cancelled", "interrupted"]
KEEP = 20  # finished jobs kept
PROGRESS_SECONDS = 1.0  # a running job's progress is saved at most this often


@dataclass
class ProtocolJob:
    """One protocol run and how far it got."""

    id: str
    spec: RunSpec
    status: JobStatus = "running"
    episodes_done: int = 0
    episodes_total: int = 0
    result: ProtocolResult | None = None
    error: str = ""
    created_at: float = field(default_factory=time.time)
    finished_at: float | None = None
    cancel: threading.Event = field(default_factory=threading.Event)
    ended: threading.Event = field(default_factory=threading.Event)
    link: WorkerLink | None = None
    saved: float = field(default_factory=time.monotonic)


def result_json(result: ProtocolResult) -> str:
    """What the store keeps of a protocol's result: its time, steps and per-demon results."""
    demons = [d.as_dict() for d in result.demons]
    return json.dumps({"seconds": result.seconds, "steps": result.steps, "demons": demons})


def result_from_json(text: str) -> ProtocolResult:
    data: dict[str, Any] = json.loads(text)
    demons = [
        DemonResult(**{**d, "counts": Counts(**d["counts"]) if d.get("counts") else None}) for d in data["demons"]
    ]
    return ProtocolResult(demons=demons, trials=[], seconds=data["seconds"], steps=data["steps"])


class ProtocolJobs:
    """The protocol jobs of one server.

    Args:
        store: where jobs are saved and loaded from at start (None: memory only).
        executor: starts the jobs' workers.
        hooks: workers honour test crashes (tests only).
    """

    def __init__(self, store: Store | None = None, executor: Executor | None = None,
                 hooks: bool = False) -> None:  # fmt: skip
        self._jobs: dict[str, ProtocolJob] = {}
        self._lock = threading.Lock()
        self._store = store
        self._executor: Executor = executor if executor is not None else ProcessExecutor()
        self._hooks = hooks
        self._stopping = False
        if store is not None:
            for record in store.list_protocol_jobs():
                try:
                    job = self._revive(record)
                except Exception as exc:  # its spec or result no longer reads (an older version's, or changed by hand)
                    log.error("protocol job %s left out: its stored row cannot be read: %s", record.id, exc)
                    continue
                self._jobs[job.id] = job

    def _revive(self, record: JobRecord) -> ProtocolJob:
        ended: tuple[JobStatus, ...] = ("finished", "failed", "cancelled", "interrupted")
        status: JobStatus = next((s for s in ended if s == record.status), "interrupted")
        job = ProtocolJob(
            record.id,
            RunSpec.model_validate_json(record.spec),
            status=status,
            episodes_done=record.done,
            episodes_total=record.total,
            result=result_from_json(record.result) if record.result else None,
            error=record.error,
            created_at=record.created_at,
            finished_at=record.finished_at,
        )
        if record.status == "running":
            job.error = f"the server stopped after {record.done} of {record.total} episodes; start the protocol again"
            job.finished_at = record.updated_at
            self._save(job)
        return job

    def _save(self, job: ProtocolJob) -> None:
        """Write the job to the store; a storage error is logged (the job goes on)."""
        if self._store is None:
            return
        try:
            self._store.save_protocol_job(
                JobRecord(
                    id=job.id,
                    spec=job.spec.model_dump_json(by_alias=True),
                    status=job.status,
                    done=job.episodes_done,
                    total=job.episodes_total,
                    result=result_json(job.result) if job.result is not None else None,
                    error=job.error,
                    created_at=job.created_at,
                    updated_at=time.time(),
                    finished_at=job.finished_at,
                )
            )
        except Exception as exc:
            log.error("could not save protocol job %s", job.id, exc_info=exc)

    def start(self, spec: RunSpec) -> ProtocolJob:
        """Start the spec's protocol in a worker of its own.

        Raises:
            BusyError: a protocol is running already.
        """
        with self._lock:
            if any(job.status == "running" for job in self._jobs.values()):
                raise BusyError("a protocol is running already (one at a time); wait for it or cancel it")
            job = ProtocolJob(secrets.token_hex(6), spec, episodes_total=spec.protocol.trials * spec.protocol.episodes)
            self._jobs[job.id] = job
            finished = [j for j in self._jobs.values() if j.status != "running"]
            forgotten = sorted(finished, key=lambda j: j.created_at)[: max(0, len(finished) - KEEP)]
            for old in forgotten:
                del self._jobs[old.id]
        self._save(job)
        for old in forgotten:
            self._forget(old.id)
        worker = _JobWorker(self, job)
        try:
            job.link = self._executor.spawn(serve_protocol, ProtocolInit(job.id, spec, self._hooks), worker)
        except Exception as exc:  # no worker: the job fails at once, saying why
            self._end(job, "failed", f"its worker did not start: {exc}")
        return job

    def _progress(self, job: ProtocolJob, done: int) -> None:
        job.episodes_done = done
        if time.monotonic() - job.saved >= PROGRESS_SECONDS:
            job.saved = time.monotonic()
            self._save(job)

    def _end(self, job: ProtocolJob, status: JobStatus, error: str = "", result: ProtocolResult | None = None) -> None:
        """The job ended (the switchboard's thread, or the caller's): saved with how, its worker let go."""
        if job.status != "running":
            return
        job.status, job.error, job.result = status, error, result
        job.finished_at = time.time()
        self._save(job)
        if job.link is not None:
            job.link.stopping = True
        job.ended.set()

    def _forget(self, job_id: str) -> None:
        if self._store is not None:
            try:
                self._store.delete_protocol_job(job_id)
            except Exception as exc:
                log.error("could not delete protocol job %s", job_id, exc_info=exc)

    def list(self) -> list[ProtocolJob]:
        with self._lock:
            return sorted(self._jobs.values(), key=lambda j: j.created_at)

    def get(self, job_id: str) -> ProtocolJob:
        with self._lock:
            job = self._jobs.get(job_id)
        if job is None:
            raise NotFoundError(f"no protocol job {job_id!r}")
        return job

    def cancel(self, job_id: str) -> ProtocolJob:
        """Ask a running job to stop (at its next episode); a finished job is forgotten instead."""
        job = self.get(job_id)
        if job.status == "running":
            job.cancel.set()
            self._send_cancel(job)
        else:
            with self._lock:
                self._jobs.pop(job_id, None)
            self._forget(job_id)
        return job

    def _send_cancel(self, job: ProtocolJob) -> None:
        if job.link is not None:
            with contextlib.suppress(WorkerGoneError):
                job.link.send(Cancel(0))

    def stop(self) -> None:
        """Stop the running job (it is saved as interrupted) and end its worker."""
        self._stopping = True
        for job in self.list():
            if job.status == "running":
                job.cancel.set()
                self._send_cancel(job)
        for job in self.list():
            if job.link is not None:
                job.ended.wait(10)
                if job.status == "running":  # its worker did not answer the cancel
                    self._end(job, "interrupted", f"the server stopped after {job.episodes_done} of "
                                                  f"{job.episodes_total} episodes")  # fmt: skip
                job.link.stop()


class _JobWorker:
    """What a protocol job's worker says (`executor.Listener`)."""

    def __init__(self, jobs: ProtocolJobs, job: ProtocolJob) -> None:
        self.jobs = jobs
        self.job = job

    def on_message(self, message: FromWorker) -> None:
        job = self.job
        if isinstance(message, Progress):
            self.jobs._progress(job, message.done)
        elif isinstance(message, Finished):
            if message.failure is None:
                self.jobs._end(job, "finished", result=message.value)
            elif message.failure.kind == "stopped":
                if self.jobs._stopping:
                    self.jobs._end(job, "interrupted", f"the server stopped after {job.episodes_done} of "
                                                       f"{job.episodes_total} episodes")  # fmt: skip
                else:
                    self.jobs._end(job, "cancelled")
            else:
                self.jobs._end(job, "failed", message.failure.message)

    def on_reply(self, command: Command | None, reply: Reply) -> None:
        pass

    def on_exit(self, reason: str) -> None:
        self.jobs._end(self.job, "failed", f"its worker died ({reason}) after {self.job.episodes_done} of "
                                           f"{self.job.episodes_total} episodes")  # fmt: skip

    def on_stall(self, seconds: float, doing: str) -> None:
        if seconds > 0:
            log.error("protocol job %s: %s", self.job.id, stall_words(seconds, doing))
