"""Protocol jobs: a scenario's whole protocol (trials x episodes, Monte-Carlo truth, test runs), run in
the background for the server, as `horde run` runs it on the command line.

One job runs at a time (the protocol uses a whole core); the results of the last `KEEP` jobs are
kept in memory (a restart forgets them: `horde run --json` is the way to keep results).
"""

from __future__ import annotations

import secrets
import threading
import time
from dataclasses import dataclass, field
from typing import Literal

from horde.core.experiment import ProtocolResult, run_protocol
from horde.errors import BusyError, NotFoundError
from horde.spec import RunSpec

JobStatus = Literal["running", "finished", "failed", "cancelled"]
KEEP = 20  # finished jobs kept


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


class ProtocolJobs:
    """The protocol jobs of one server."""

    def __init__(self) -> None:
        self._jobs: dict[str, ProtocolJob] = {}
        self._lock = threading.Lock()
        self._threads: list[threading.Thread] = []

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
            for old in sorted(finished, key=lambda j: j.created_at)[: max(0, len(finished) - KEEP)]:
                del self._jobs[old.id]
        thread = threading.Thread(target=self._run, args=(job,), name=f"protocol-{job.id}", daemon=True)
        self._threads.append(thread)
        thread.start()
        return job

    def _run(self, job: ProtocolJob) -> None:
        def progress(done: int, total: int) -> None:
            job.episodes_done = done
            if job.cancel.is_set():
                raise _CancelledError

        try:
            job.result = run_protocol(job.spec, progress)
            job.status = "finished"
        except _CancelledError:
            job.status = "cancelled"
        except Exception as exc:  # a protocol that fails must not take the server's thread with it
            job.status, job.error = "failed", f"{type(exc).__name__}: {exc}"
        job.finished_at = time.time()

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
        return job

    def stop(self) -> None:
        for job in self.list():
            job.cancel.set()
        for thread in self._threads:
            thread.join(timeout=10)
