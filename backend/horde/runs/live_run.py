"""One live run: a learner thread that steps its session and answers the commands that reach it.

A live run is three parts, each with one job:

- `LiveRun` (here): the learner thread, its pacing (full speed in chunks, or `hz` steps a second) and the
  commands. Other threads talk to it in two ways: commands (start, pause, step, add a demon, export a
  snapshot, ...) go through a queue (`commands.CommandQueue`) and come back as a result or an exception;
  readers take `view`, an immutable `RunView` published after every chunk.
- `RunSession` (session.py): the rules: the source of transitions it steps (the grid world, or a
  Gymnasium environment), the status, the protocol's episode loop and stopping rule, divergence, what
  each command may do.
- `Recorder` (recorder.py): history rows, publication, snapshots and saves to the store.

At full speed (hz = None) the thread learns in chunks of about 20 ms and looks at its queue between
them; with `hz` it paces its steps and waits on the queue in between, so a command is answered at once.
A live run is the first trial of its protocol: it is seeded as `run_trial(spec, 0)` is and runs the same
episode loop, and it finishes when the protocol's episodes are done (or its stopping rule fires);
with `protocol.episodes = 0` it runs until paused. The learner thread never dies of bad input or a
numerical accident: an exception while learning marks the run `failed` with the exception's message.
"""

from __future__ import annotations

import contextlib
import logging
import os
import threading
import time
from collections.abc import Callable
from typing import TypeVar

import numpy as np

from horde.runs.commands import CommandQueue, ShutdownError
from horde.runs.errors import BusyError, NotFoundError, SaveError
from horde.runs.events import EventLog
from horde.runs.history import History
from horde.runs.recorder import Recorder, SnapshotCost
from horde.runs.run_setup import Limits
from horde.runs.run_view import RunStatus, RunView, Summary
from horde.runs.saver import Saver
from horde.runs.session import RunSession, Source
from horde.runs.snapshot import Snapshot, capture
from horde.runs.store import Store
from horde.spec import BehaviourSpec, DemonSpec

log = logging.getLogger(__name__)

T = TypeVar("T")

CHUNK_SECONDS = 0.02  # full speed: learn this long between looks at the command queue
MAX_LAG = 0.1  # hz pacing: time lost beyond this is not caught up
MAX_WAIT = 1.0  # hz pacing: the longest single wait for the next step (then the loop looks again)
COMMAND_TIMEOUT = 600.0  # a command waits this long for the learner thread at most
LEARNER_NICENESS = 10


def _lower_priority() -> None:
    """Give this learner thread a lower OS priority than the server's own threads.

    The compiled loop releases the GIL, so learners use every core; niced, they yield the CPU whenever
    the event loop has requests or streams to serve and take all of it otherwise.
    """
    with contextlib.suppress(AttributeError, OSError):  # per-thread niceness is a Linux feature
        os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), LEARNER_NICENESS)


class LiveRun:
    """A run and its learner thread.

    Args:
        run_id: the run's id.
        sim: the source of transitions (fresh, or restored from a snapshot); its spec is the run's spec.
        limits: the server's size limits and timings.
        store: where the run saves itself (None: nowhere).
        status, hz, message, created_at, summary: the run's state when it is restored.
        stop_reference: the stopping rule's reference weights (default: the current weights).
        saver: the writer thread that periodic snapshots are handed to (None: written in this thread).
    """

    def __init__(
        self,
        run_id: str,
        sim: Source,
        limits: Limits,
        store: Store | None = None,
        *,
        status: RunStatus = "created",
        hz: float | None = None,
        message: str = "",
        created_at: float | None = None,
        summary: Summary | None = None,
        stop_reference: list[np.ndarray] | None = None,
        saver: Saver | None = None,
    ) -> None:
        self.id = run_id
        self.limits = limits
        self.session = RunSession(sim, limits, status=status, hz=hz, message=message, summary=summary,
                                  stop_reference=stop_reference)  # fmt: skip
        self.recorder = Recorder(run_id, limits, store, saver, created_at if created_at is not None else time.time(),
                                 sim.horde.names)  # fmt: skip
        self.session.recorder = self.recorder
        self._commands = CommandQueue(f"run {run_id!r}")
        self._thread = threading.Thread(target=self._loop, name=f"horde-run-{run_id}", daemon=True)
        self._next_step_at = 0.0
        self.recorder.publish(self.session)

    @property
    def view(self) -> RunView:
        """The latest published view (immutable; any thread)."""
        view = self.recorder.view
        assert view is not None
        return view

    @property
    def history(self) -> History:
        return self.recorder.history

    @property
    def events(self) -> EventLog:
        return self.session.events

    @property
    def snapshot_cost(self) -> SnapshotCost:
        return self.recorder.snapshot_cost

    # ------------------------------------------------------------------------------------------
    # Life cycle (called from other threads)

    def start_thread(self) -> None:
        self._thread.start()

    def save(self) -> None:
        """Write the run and a snapshot to the store; only before `start_thread`.

        Raises:
            SaveError: the store refused the write.
        """
        self.recorder.persist(self.session, snapshot=True)

    def close(self, timeout: float = 60.0) -> None:
        """Stop the learner thread; a running run is saved as paused with a fresh snapshot.

        Raises:
            BusyError: the learner thread is still busy after `timeout` seconds (it stops once it gets
                to the shutdown command, which stays queued; closing again later finds it stopped).
            SaveError: the thread stopped, but its last save failed.
        """
        if not self._thread.is_alive():
            return
        failure: SaveError | None = None
        try:
            self.call(self._shutdown, timeout)
        except SaveError as exc:
            failure = exc
        except (NotFoundError, BusyError):
            pass  # closed already, or busy: the join below tells
        self._thread.join(timeout)
        if self._thread.is_alive():
            log.error("run %s: the learner thread did not stop within %s s", self.id, timeout)
            raise BusyError(f"run {self.id!r} did not stop within {timeout:g} s; it stops when its current work ends")
        if failure is not None:
            raise failure

    def is_alive(self) -> bool:
        return self._thread.is_alive()

    def call(self, action: Callable[[], T], timeout: float | None = COMMAND_TIMEOUT) -> T:
        """Run `action` in the learner thread and return its result (or raise its exception).

        Raises:
            NotFoundError: the run has been closed (deleted).
            BusyError: the learner thread did not get to the command within `timeout`.
        """
        return self._commands.call(action, timeout)

    # ------------------------------------------------------------------------------------------
    # Commands: the session's rule, then a save and a publication (each runs in the learner thread)

    def _then_commit(self, rule: Callable[[], None], snapshot: bool = True) -> Callable[[], RunView]:
        def command() -> RunView:
            rule()
            return self.recorder.commit(self.session, snapshot)

        return command

    def start(self) -> RunView:
        def rule() -> None:
            self.session.start()
            self._next_step_at = time.monotonic()

        return self.call(self._then_commit(rule, snapshot=False))

    def pause(self) -> RunView:
        return self.call(self._then_commit(self.session.pause))

    def reset(self) -> RunView:
        return self.call(self._then_commit(self.session.reset))

    def step(self, steps: int) -> RunView:
        def command() -> RunView:
            self.session.step(steps)
            if self.session.status == "paused":  # a finished run saved itself when it finished
                return self.recorder.commit(self.session, snapshot=True)
            return self.recorder.publish(self.session)

        return self.call(command)

    def patch(
        self, *, set_hz: bool = False, hz: float | None = None, behaviour: BehaviourSpec | None = None
    ) -> RunView:
        """Change the speed (when `set_hz`; None is full speed) and/or the behaviour policy."""

        def rule() -> None:
            self.session.patch(set_hz, hz, behaviour)
            if set_hz:
                self._next_step_at = time.monotonic()

        return self.call(self._then_commit(rule))

    def add_demon(self, demon: DemonSpec) -> RunView:
        return self.call(self._then_commit(lambda: self.session.add_demon(demon)))

    def remove_demon(self, name: str) -> RunView:
        return self.call(self._then_commit(lambda: self.session.remove_demon(name, self.id)))

    def snapshot(self) -> Snapshot:
        session = self.session
        return self.call(lambda: capture(session.sim, session.spec, session.status, session.hz,
                                         session.stop_reference))  # fmt: skip

    def _shutdown(self) -> None:
        """Save the run (a running one as paused), refuse further commands, and leave the loop."""
        session = self.session
        if session.status == "running":
            session.set_status("paused", f"paused at step {session.sim.total_steps} when the server stopped")
        failure: SaveError | None = None
        try:
            self.recorder.persist(session, snapshot=session.status != "failed")
        except SaveError as exc:
            failure = exc
        self.recorder.publish(session)
        self._commands.close()
        raise ShutdownError(failure)

    # ------------------------------------------------------------------------------------------
    # The learner thread

    def _loop(self) -> None:
        _lower_priority()
        while True:
            try:
                if self.session.status != "running":
                    command = self._commands.next()
                    if command is not None:
                        self._commands.run(command)
                elif self.session.hz is None:
                    self._run_chunk()
                else:
                    self._run_paced()
            except ShutdownError:
                return
            except Exception as exc:  # the learner thread never dies
                self.session.fail(exc)

    def _run_chunk(self) -> None:
        """Full speed: commands first, then about CHUNK_SECONDS of learning."""
        self._commands.drain()
        session = self.session
        if session.status != "running" or session.hz is not None:
            return
        session.learn(None, time.monotonic() + CHUNK_SECONDS)
        self.recorder.publish(session, force=False)
        self.recorder.maybe_snapshot(session)

    def _run_paced(self) -> None:
        """hz pacing: wait for the next step's time (answering commands meanwhile), then step."""
        wait = self._next_step_at - time.monotonic()
        if wait > 0:
            command = self._commands.next(min(wait, MAX_WAIT))
            if command is not None:
                self._commands.run(command)
                return
            if wait > MAX_WAIT:
                return  # not due yet: look at the queue again
        self._commands.drain()
        session = self.session
        if session.status != "running" or session.hz is None:
            return
        hz = session.hz
        now = time.monotonic()
        due = min(1 + int((now - self._next_step_at) * hz), max(1, int(hz * CHUNK_SECONDS)))
        session.learn(due, None)
        self._next_step_at = max(self._next_step_at + due / hz, now - MAX_LAG)
        self.recorder.publish(session, force=False)
        self.recorder.maybe_snapshot(session)
