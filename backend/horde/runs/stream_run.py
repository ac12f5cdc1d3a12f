"""Stream runs: a stream world's Horde learning the records that clients push, in order, one run at a time.

Each stream run learns in a worker of its own (`job_workers.serve_stream`, over a `StreamLearning`); the API
process holds a `StreamRun`, which the REST route and the WebSocket route (server/routes/records.py) both
feed: every batch is sent to the worker and learned whole, in the order it arrives. `StreamRuns` is the
server's registry of them (bounded; kept in memory only). A stream run whose worker died is failed: its
calls are 409s naming why, until it is deleted.
"""

from __future__ import annotations

import contextlib
import logging
import threading
import time
import uuid
from typing import Any

import numpy as np

from horde.core.learner import Readout
from horde.runs import messages as m
from horde.runs.errors import BusyError, ConflictError, FieldProblem, NotFoundError, SpecError
from horde.runs.executor import ProcessExecutor
from horde.runs.job_workers import serve_stream
from horde.runs.link import Executor, WorkerGoneError, WorkerLink, stall_words
from horde.runs.run_view import is_control
from horde.runs.stream_learning import (
    HISTORY,
    MAX_RECORDS_PER_BATCH,
    PushResult,
    StreamHistory,
)
from horde.runs.stream_snapshot import StreamSnapshot
from horde.spec import RunSpec
from horde.worlds.phase_plane import Axis

log = logging.getLogger(__name__)

MAX_STREAM_RUNS = 16
__all__ = ["HISTORY", "MAX_RECORDS_PER_BATCH", "MAX_STREAM_RUNS", "PushResult", "StreamRun", "StreamRuns"]


class StreamRun:
    """One stream run, learning in its worker; its counters as the last batch left them.

    Args:
        run_id: the id the routes name it by.
        spec: a run spec whose world is of kind "stream".
    """

    def __init__(self, run_id: str, spec: RunSpec) -> None:
        self.id = run_id
        self.spec = spec
        self.names = [d.name for d in spec.demons]
        self.control = [is_control(d) for d in spec.demons]
        self.created = time.time()
        self.link: WorkerLink | None = None
        self.failed = ""  # why its worker ended, when it died
        self._status = PushResult(0, 0, [], np.zeros(len(self.names)), 0.0)
        self._lock = threading.Lock()  # one batch at a time, in the order they come

    # ------------------------------------------------------------------------------------------
    # What the worker says (the switchboard's thread)

    def on_message(self, message: m.FromWorker) -> None:
        pass

    def on_reply(self, command: m.Command | None, reply: m.Reply) -> None:
        if isinstance(reply.value, PushResult):
            self._status = reply.value

    def on_exit(self, reason: str) -> None:
        self.failed = f"its worker died ({reason})"
        log.error("stream run %s: %s", self.id, self.failed)

    def on_stall(self, seconds: float, doing: str) -> None:
        if seconds > 0:
            log.error("stream run %s: %s", self.id, stall_words(seconds, doing))

    # ------------------------------------------------------------------------------------------
    # Calls

    def _call(self, command: m.Command, action: str) -> Any:
        link = self.link
        if link is None or link.gone():
            raise self._failed(action)
        try:
            reply, _ = link.call(command)
        except WorkerGoneError:
            raise self._failed(action) from None
        except BusyError as exc:
            raise ConflictError(f"cannot {action} stream run {self.id!r} now: {exc}") from None
        if reply.failure is not None:
            m.raise_failure(reply.failure)
        return reply.value

    def _failed(self, action: str) -> ConflictError:
        why = self.failed or "its worker ended"
        return ConflictError(f"cannot {action} stream run {self.id!r}: it failed, {why}; delete it")

    def status(self) -> PushResult:
        """The counters and predictions as the last batch left them."""
        return self._status

    def push(self, items: list[Any], whole: bool = False) -> PushResult:
        """Learn a batch's good records, in order (with `whole`, none of a batch with a refused record)."""
        with self._lock:
            result: PushResult = self._call(m.Push(items, whole), "push records to")
        return result

    def phase_plane(self, demon: str, x: str, y: str, resolution: int) -> tuple[Axis, Axis, np.ndarray, np.ndarray]:
        """(x axis, y axis, [R, R] the demon's values over the plane, [N, 2] the recent (x, y) readings).

        Raises:
            SpecError: an unknown demon or sensor (422 naming the query parameter).
        """
        result: tuple[Axis, Axis, np.ndarray, np.ndarray] = self._call(m.StreamPhaseOf(demon, x, y, resolution),
                                                                       "read the phase plane of")  # fmt: skip
        return result

    def history(self, sensors: list[str], demons: list[str], last: int) -> StreamHistory:
        result: StreamHistory = self._call(m.StreamHistoryOf(sensors, demons, last), "read the history of")
        return result

    def readout(self) -> tuple[Readout, np.ndarray]:
        """Every demon's numbers at the last observation (the demon table's), and [D] their step sizes now."""
        result: tuple[Readout, np.ndarray] = self._call(m.StreamReadoutOf(), "read the demons of")
        return result

    def snapshot(self) -> bytes:
        """The learner's state now, between two batches, as a `StreamSnapshot` document (JSON bytes)."""
        data: bytes = self._call(m.Export(), "export")
        return data

    def crash(self, how: m.CrashKind) -> None:
        """Tests only: make the worker crash."""
        if self.link is not None:
            self.link.send(m.Call(0, m.Crash(how)))

    def close(self) -> None:
        link = self.link
        if link is None:
            return
        link.stopping = True
        if link.alive:
            with contextlib.suppress(WorkerGoneError, BusyError):
                link.call(m.Shutdown(), 10.0)
        link.stop()


class StreamRuns:
    """The server's stream runs by id (at most MAX_STREAM_RUNS at once), each in a worker of its own.

    Args:
        executor: starts the workers (default: processes of this machine, stopped with `stop`).
        hooks: workers honour test crashes (tests only).
    """

    def __init__(self, executor: Executor | None = None, hooks: bool = False) -> None:
        self._owns_executor = executor is None
        self.executor: Executor = executor if executor is not None else ProcessExecutor()
        self.hooks = hooks
        self._runs: dict[str, StreamRun] = {}
        self._making = 0
        self._lock = threading.Lock()

    def create(self, spec: RunSpec, snapshot: StreamSnapshot | None = None) -> StreamRun:
        """A new stream run (going on from `snapshot` if given). Raises SpecError (422 at world.kind) for another
        world kind, BusyError when full."""
        if spec.world.kind != "stream":
            message = f"a stream run needs world.kind = 'stream', not {spec.world.kind!r}"
            raise SpecError([FieldProblem(("body", "world", "kind"), message)])
        with self._lock:
            if len(self._runs) + self._making >= MAX_STREAM_RUNS:
                raise BusyError(f"{MAX_STREAM_RUNS} stream runs exist already; delete one first")
            self._making += 1
        try:
            run = StreamRun(uuid.uuid4().hex[:12], spec)
            link = self.executor.spawn(serve_stream, m.StreamInit(run.id, spec, snapshot, self.hooks), run)
            try:
                ready = link.wait_ready()
            except (WorkerGoneError, BusyError) as exc:
                link.stop()
                raise ConflictError(f"the stream run's worker did not start: {exc}") from None
            if ready.failure is not None:
                link.stop()
                m.raise_failure(ready.failure)
            run.link = link
            if isinstance(ready.value, PushResult):
                run._status = ready.value
            with self._lock:
                self._runs[run.id] = run
        finally:
            with self._lock:
                self._making -= 1
        return run

    def import_snapshot(self, snapshot: StreamSnapshot) -> StreamRun:
        """A new stream run that learns the next record exactly as the snapshot's run would have.

        Raises:
            SpecError: a snapshot of another world kind (422 at spec.world.kind), or arrays that do not fit.
        """
        if snapshot.spec.world.kind != "stream":
            message = f"a stream run needs world.kind = 'stream', not {snapshot.spec.world.kind!r}"
            raise SpecError([FieldProblem(("body", "spec", "world", "kind"), message)])
        return self.create(snapshot.spec, snapshot)

    def get(self, run_id: str) -> StreamRun:
        with self._lock:
            run = self._runs.get(run_id)
        if run is None:
            raise NotFoundError(f"no stream run {run_id!r}")
        return run

    def delete(self, run_id: str) -> None:
        with self._lock:
            run = self._runs.pop(run_id, None)
        if run is None:
            raise NotFoundError(f"no stream run {run_id!r}")
        run.close()

    def holds(self, run: StreamRun) -> bool:
        """Whether this very run is still registered (not deleted)."""
        with self._lock:
            return self._runs.get(run.id) is run

    def list(self) -> list[StreamRun]:
        with self._lock:
            return list(self._runs.values())

    def stop(self) -> None:
        """End every stream run's worker (stream runs live in memory only)."""
        with self._lock:
            runs, self._runs = list(self._runs.values()), {}
        for run in runs:
            run.close()
        if self._owns_executor:
            self.executor.stop()
