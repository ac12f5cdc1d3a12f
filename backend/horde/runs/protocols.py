"""Protocol jobs: a scenario's whole protocol (trials x episodes, Monte-Carlo truth, test runs), run in
the background for the server, as `horde run` runs it on the command line.

One job runs at a time (the protocol uses a whole core); the last `KEEP` jobs are kept. With a store,
every job is saved there as it starts, with its progress at most every `PROGRESS_SECONDS`, and with its
result when it ends: after a restart the finished jobs are back as they were, and a job that was
running when the server stopped (or died) is back as `interrupted`, with how far it got.
"""

from __future__ import annotations

import json
import logging
import secrets
import threading
import time
from dataclasses import dataclass, field
from typing import Any, Literal

from horde.core.experiment import DemonResult, ProtocolResult, run_protocol
from horde.runs.errors import BusyError, NotFoundError
from horde.runs.store import JobRecord, Store
from horde.spec import Counts, RunSpec

log = logging.getLogger(__name__)

JobStatus = Literal["running", "finished", "failed", "cancelled", "interrupted"]
KEEP = 20  # finished jobs kept
PROGRESS_SECONDS = 1.0  # a running job's progress is saved at most this often


class _CancelledError(Exception):
    pass


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
    """

    def __init__(self, store: Store | None = None) -> None:
        self._jobs: dict[str, ProtocolJob] = {}
        self._lock = threading.Lock()
        self._threads: list[threading.Thread] = []
        self._store = store
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
        """Start the spec's protocol in a background thread.

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
        thread = threading.Thread(target=self._run, args=(job,), name=f"protocol-{job.id}", daemon=True)
        self._threads.append(thread)
        thread.start()
        return job

    def _forget(self, job_id: str) -> None:
        if self._store is not None:
            try:
                self._store.delete_protocol_job(job_id)
            except Exception as exc:
                log.error("could not delete protocol job %s", job_id, exc_info=exc)

    def _run(self, job: ProtocolJob) -> None:
        saved = time.monotonic()

        def progress(done: int, total: int) -> None:
            nonlocal saved
            job.episodes_done = done
            if job.cancel.is_set():
                raise _CancelledError
            if time.monotonic() - saved >= PROGRESS_SECONDS:
                saved = time.monotonic()
                self._save(job)

        try:
            job.result = run_protocol(job.spec, progress)
            job.status = "finished"
        except _CancelledError:
            if self._stopping:
                job.status = "interrupted"
                job.error = f"the server stopped after {job.episodes_done} of {job.episodes_total} episodes"
            else:
                job.status = "cancelled"
        except Exception as exc:  # a protocol that fails must not take the server's thread with it
            job.status, job.error = "failed", f"{type(exc).__name__}: {exc}"
        job.finished_at = time.time()
        self._save(job)

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
        else:
            with self._lock:
                self._jobs.pop(job_id, None)
            self._forget(job_id)
        return job

    def stop(self) -> None:
        """Stop the running job (it is saved as interrupted) and wait for its thread."""
        self._stopping = True
        for job in self.list():
            job.cancel.set()
        for thread in self._threads:
            thread.join(timeout=10)
