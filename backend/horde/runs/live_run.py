"""One live run as the API process holds it: what its worker published, and the commands it sends the worker.

The run learns in its worker (`worker.RunWorker`, a process of this machine or a Ray actor). Here is its
public face, which the routes, the stream hub and the live view read, as before the runs left the process:

- `view`: an immutable `RunView` made of the latest view the worker published, the spec, and what the API
  process knows itself (a save that failed: "; not saved: <why>"; a worker that stopped answering; a worker
  that died). `history` and `events` are kept here, fed by the worker's updates.
- the commands (`start`, `pause`, `reset`, `step`, `patch`, `add_demon`, `remove_demon`, `snapshot`, value maps,
  greedy actions, phase planes, Baird's star, `evaluate`) are calls to the worker; each answers with the view
  after it, once the save it made is written.

Saves: the worker sends what must be saved (`messages.Save`), the API process writes it (in the manager's
saver thread, in order). A save a command made is written before the command answers; a failed one raises
SaveError (503) and stays on the run's message until a save works again.

Why about 420 lines: the run's face, its mirror of the worker's updates and its saves are one object, as readers,
commands and the writer thread share its lock and its view.

A worker that dies fails its run alone: the run is `failed`, the reason in its message and events, its latest
snapshot kept in the store; a command for it is a 409 naming that state. Reset starts a fresh worker.
"""

from __future__ import annotations

import contextlib
import logging
import pickle
import threading
import time
from collections.abc import Callable
from concurrent.futures import Future
from typing import Any

import numpy as np

from horde.runs import messages as m
from horde.runs.collector import building
from horde.runs.errors import BusyError, ConflictError, NotFoundError, SaveError
from horde.runs.events import EventLog
from horde.runs.history import History, quantities_of
from horde.runs.link import COMMAND_TIMEOUT, Listener, WorkerGoneError, WorkerLink, stall_words
from horde.runs.run_setup import Limits
from horde.runs.run_view import RunStatus, RunView, Summary, Worker, published_view, stored_view
from horde.runs.saver import Saver
from horde.runs.store import RunRecord, Store
from horde.spec import BehaviourSpec, DemonSpec, RunSpec

log = logging.getLogger(__name__)

NOT_SAVED = "; not saved: "  # what a run's message adds when its latest waited save failed
Spawn = Callable[[m.RunInit, Listener], WorkerLink]  # starts a run's worker (the manager's executor)


class LiveRun:
    """A run, its worker and what it published.

    Args:
        run_id: the run's id.
        spec: its spec (the API's copy, kept in step with the worker's as demons join and leave).
        limits: the server's size limits and timings.
        spawn: starts a worker for this run.
        store, saver: where saves are written, and by which thread (None: nowhere).
        created_at: the run's creation time.
        hooks: workers honour test crashes (HORDE_TEST_HOOKS).
    """

    def __init__(self, run_id: str, spec: RunSpec | None, limits: Limits, spawn: Spawn, store: Store | None = None,
                 saver: Saver | None = None, created_at: float | None = None, hooks: bool = False) -> None:  # fmt: skip
        self.id = run_id
        self.spec: RunSpec = spec if spec is not None else RunSpec()  # a run built from data: its spec comes later
        self.limits = limits
        self.store = store
        self.saver = saver
        self.created_at = created_at if created_at is not None else time.time()
        self.hooks = hooks
        self._spawn = spawn
        self.history = self._new_history()
        self.events = EventLog(limits.events)
        self.link: WorkerLink | None = None
        self._lock = threading.Lock()
        self._published: m.PublishedView | None = None
        self._not_saved = ""  # why the latest waited save failed
        self._stall = ""  # how long the worker has not answered
        self._gone = ""  # why the worker ended (a failed run's message)
        self._snapshot_steps: int | None = None  # the step of the latest snapshot written
        self._newest_save = 0  # the highest save id of this worker handed to the writer
        self._closed = False
        self.on_status: Callable[[], None] = lambda: None  # told when the published status changes
        self.threads: int | None = None  # the share of the cores its worker was last given
        self._launched = False  # updates that come before the worker's Ready is taken in wait for it
        self._early: list[m.Update] = []
        self._view = stored_view(run_id, self.spec, "created", "", None, self.created_at)

    def _new_history(self) -> History:
        return History(self.names, self.limits.history, self.limits.history_every, quantities_of(self.spec))

    @property
    def names(self) -> list[str]:
        return [d.name for d in self.spec.demons]

    @property
    def view(self) -> RunView:
        """The latest view (immutable; any thread)."""
        return self._view

    def is_alive(self) -> bool:
        """Whether the run is still listed (not closed); a run whose worker died is listed, and failed."""
        return not self._closed

    # ------------------------------------------------------------------------------------------
    # Life cycle

    def launch(self, init: m.RunInit) -> RunView:
        """Start a worker for the run and wait until it is ready (a new run's first save written).

        Raises:
            SpecError and the other run errors: the worker could not build the run (it has ended).
            SaveError: the first save failed (the worker has ended: the run was not made).
            BusyError: the worker was not ready in time (it has been stopped).
        """
        link = self._spawn(init, self)
        try:
            ready = link.wait_ready()
        except (WorkerGoneError, BusyError) as exc:
            self._stop_link(link)
            raise ConflictError(f"run {self.id!r} could not start its worker: {exc}") from None
        if ready.failure is not None:
            self._stop_link(link)
            m.raise_failure(ready.failure)
        if ready.spec is not None:  # validated by the worker: loaded here without a collection on the way
            with building():
                spec = pickle.loads(ready.spec)
            self.spec = spec
            self.history = self._new_history()
        with self._lock:
            self.link, self._gone, self._stall = link, "", ""
            self._newest_save = 0  # a new worker numbers its saves from 1
            early, self._early, self._launched = self._early, [], True
        for update in [ready.value, *early] if isinstance(ready.value, m.Update) else early:
            self._apply(update)
        if ready.save is not None:
            try:
                self._write(ready.save, waited=True).result(COMMAND_TIMEOUT)
            except Exception:
                self._stop_link(link)
                raise
        return self.view

    def close(self, timeout: float = 60.0, save: bool = True) -> None:
        """End the worker: with `save`, a running run is saved as paused first (a failed save raises SaveError, the
        worker ended all the same). A worker that does not answer within `timeout` is killed."""
        self._closed = True
        link = self.link
        if link is None or not link.alive:
            return
        failure: Exception | None = None
        link.stopping = True  # its end is no news (and fails nothing), however soon it comes
        try:
            _, written = link.call(m.Shutdown(save), timeout)
            if written is not None:
                written.result(COMMAND_TIMEOUT)
        except SaveError as exc:
            failure = exc
        except (WorkerGoneError, BusyError) as exc:
            log.error("run %s: its worker did not shut down (%s); it is stopped", self.id, exc)
        self._stop_link(link)
        if failure is not None:
            raise failure

    def _stop_link(self, link: WorkerLink) -> None:
        link.stop()

    # ------------------------------------------------------------------------------------------
    # What the worker says (the switchboard's thread)

    def on_message(self, message: m.FromWorker) -> None:
        if isinstance(message, m.Update):
            self._apply(message)
        elif isinstance(message, m.Save):
            self._write(message, waited=False)

    def on_reply(self, command: m.Command | None, reply: m.Reply) -> Future[float] | None:
        """Keep the spec in step with a command that changed it, then apply the reply's update and hand its save
        to the writer (the caller waits for that)."""
        if reply.failure is None and command is not None:
            self._follow(command)
        if reply.update is not None:
            self._apply(reply.update)
        return self._write(reply.save, waited=True) if reply.save is not None else None

    def _follow(self, command: m.Command) -> None:
        spec = self.spec
        if isinstance(command, m.AddDemon):
            spec = spec.model_copy(update={"demons": [*spec.demons, command.demon]})
        elif isinstance(command, m.RemoveDemon):
            spec = spec.model_copy(update={"demons": [d for d in spec.demons if d.name != command.name]})
        elif isinstance(command, m.Patch) and command.behaviour is not None:
            spec = spec.model_copy(update={"behaviour": command.behaviour})
        self.spec = spec

    def _apply(self, update: m.Update) -> None:
        with self._lock:
            if not self._launched:  # the worker's Ready (and the spec it brings) comes first
                self._early.append(update)
                return
            if update.history == "remap":  # the demons changed: the rows of those still there are kept
                self.history = self.history.remap(self.names)
            elif update.history == "new":  # a reset run
                self.history = self._new_history()
            rows = update.rows
            if rows is not None and rows.values.shape[::2] == (len(self.history.quantities), len(self.history.names)):
                for k, step in enumerate(rows.steps):
                    self.history.record(int(step), *rows.values[:, k])
            if update.skipped:
                self.events.skip(update.skipped)
            for e in update.events:
                self.events.add(e.step, e.episode, e.kind, e.message, e.value)
            changed = update.view is not None and (self._published is None
                                                   or update.view.status != self._published.status)  # fmt: skip
            if update.view is not None:
                self._published = update.view
            self._refresh()
        if changed:
            self.on_status()

    def on_exit(self, reason: str) -> None:
        """The worker died: the run fails alone, saying why; its latest snapshot stays in the store."""
        with self._lock:
            published = self._published
            steps = published.total_steps if published is not None else 0
            kept = (f"its latest snapshot (step {self._snapshot_steps}) is kept" if self._snapshot_steps is not None
                    else "no snapshot of it was saved")  # fmt: skip
            self._gone = (f"its worker died ({reason}) at step {steps}; {kept}: reset it to start afresh, "
                          "or delete it")  # fmt: skip
            self._stall = ""
            episode = published.episode if published is not None else 0
            self.events.add(steps, episode, "error", f"the worker died: {reason}")
            self._refresh()
        log.error("run %s: %s", self.id, self._gone)
        if self.store is not None and not self._closed:
            view = self.view
            record = RunRecord(id=self.id, name=self.spec.name, status="failed", message=self._gone, hz=view.hz,
                               spec=self.spec.model_dump_json(by_alias=True), episode=view.episode,
                               steps=view.total_steps, created_at=self.created_at, updated_at=time.time())  # fmt: skip
            self._write(m.Save(0, record, None, None), waited=False)

    def on_stall(self, seconds: float, doing: str) -> None:
        with self._lock:
            view = self._view
            if seconds > 0:
                self._stall = stall_words(seconds, doing)
                self.events.add(view.total_steps, view.episode, "error", self._stall)
            else:
                self._stall = ""
                self.events.add(view.total_steps, view.episode, "status", "its worker answers again")
            self._refresh()

    def _refresh(self) -> None:
        """A new view from what was published and what the API process knows (the caller holds the lock)."""
        published = self._published
        if published is None:
            return
        names = len(self.spec.demons)
        if len(published.prediction) != names:  # a view of other demons (cannot happen: replies come in order)
            return
        status, message = published.status, published.message
        if self._gone:
            status, message = "failed", self._gone
        else:
            if self._not_saved:
                message = f"{message or status}{NOT_SAVED}{self._not_saved}"
            if self._stall:
                message = f"{message or status}; {self._stall}"
        link = self.link
        worker = Worker("none")
        if link is not None:
            worker = Worker(link.kind, link.pid, link.node, link.alive)  # type: ignore[arg-type]
        self._view = published_view(self.id, self.spec, published, status, message, self.created_at,
                                    self._view.seq + 1, worker)  # fmt: skip

    def show_stored(self, record: RunRecord, summary: Summary | None) -> None:
        """Show a stored run that gets no worker (it failed before the restart): its record, as it was."""
        status: RunStatus = "failed"
        self._gone = record.message
        self._view = stored_view(self.id, self.spec, status, record.message, summary, self.created_at, record.hz,
                                 record.episode, record.steps)  # fmt: skip

    # ------------------------------------------------------------------------------------------
    # Saves (written by the manager's saver thread, in the order they came)

    def _write(self, save: m.Save, waited: bool) -> Future[float]:
        store = self.store
        future: Future[float] = Future()
        if store is None:
            future.set_result(0.0)
            return future
        if save.save_id:
            with self._lock:
                stale = save.save_id < self._newest_save
                self._newest_save = max(self._newest_save, save.save_id)
            if stale:  # a periodic snapshot encoded while a command's later save went ahead of it: it would undo it
                self._acknowledge(save.save_id, 0.0, None)
                future.set_result(0.0)
                return future

        def write() -> float:
            began = time.perf_counter()
            store.save_run(save.record, save.snapshot, save.summary)
            return time.perf_counter() - began

        done: Future[float] = self.saver.submit(write) if self.saver is not None else _now(write)
        done.add_done_callback(lambda f: self._written(save, waited, f, future))
        return future

    def _written(self, save: m.Save, waited: bool, done: Future[float], future: Future[float]) -> None:
        """A save's write ended: the message and events say what came of it, the worker hears it."""
        exc = done.exception()
        with self._lock:
            view = self._view
            if exc is None:
                self._not_saved = ""
                if save.snapshot is not None:
                    self._snapshot_steps = save.record.steps
            else:
                log.error("could not save run %s", self.id, exc_info=exc)
                self.events.add(view.total_steps, view.episode, "error", f"could not save the run: {exc}")
                if waited:
                    self._not_saved = str(exc)
            said = save.record.message or save.record.status  # what the run said when it was saved
            self._refresh()
        if save.save_id:
            self._acknowledge(save.save_id, done.result() if exc is None else 0.0, exc)
        if exc is None:
            future.set_result(done.result())
        else:
            future.set_exception(SaveError(f"run {self.id!r}: {said}, but it could not be saved: {exc}"))

    def _acknowledge(self, save_id: int, seconds: float, exc: BaseException | None) -> None:
        """Tell the worker its save was written (or failed, or was dropped as stale): its next periodic one may
        follow."""
        link = self.link
        if link is not None and link.alive:
            with contextlib.suppress(WorkerGoneError):
                link.send(m.SaveDone(save_id, seconds, None if exc is None else str(exc)))

    # ------------------------------------------------------------------------------------------
    # Commands

    def _worker(self, action: str) -> WorkerLink:
        link = self.link
        if self._closed:
            raise NotFoundError(f"run {self.id!r} has been deleted")
        if link is None or link.gone():
            view = self.view
            raise ConflictError(f"cannot {action} run {self.id!r}: it is {view.status} ({view.message})")
        return link

    def call(self, command: m.Command, action: str, timeout: float = COMMAND_TIMEOUT,
             abandoned: Callable[[], bool] | None = None) -> Any:  # fmt: skip
        """Send a command to the worker and return its value, once the save it made is written.

        Raises:
            ConflictError: the worker is gone (naming the run's state), or has stopped answering.
            BusyError: no answer within `timeout`.
            SaveError: the command's change holds, but its save failed.
            The command's own errors (ConflictError, SpecError, NotFoundError).
        """
        link = self._worker(action)
        try:
            reply, save = link.call(command, timeout, abandoned)
        except WorkerGoneError:
            view = self.view
            raise ConflictError(f"cannot {action} run {self.id!r}: it is {view.status} ({view.message})") from None
        except BusyError as exc:
            if link.stalled:
                raise ConflictError(
                    f"cannot {action} run {self.id!r} now: {exc}; try again later, or delete it"
                ) from None
            raise BusyError(f"run {self.id!r}: {exc}") from None
        if save is not None:
            save.result(COMMAND_TIMEOUT)  # raises SaveError
        if reply.failure is not None:
            m.raise_failure(reply.failure)
        return reply.value

    def start(self) -> RunView:
        self.call(m.Start(), "start")
        return self.view

    def pause(self) -> RunView:
        self.call(m.Pause(), "pause")
        return self.view

    def reset(self) -> RunView:
        """Fresh weights and generator, the current demons; a run whose worker is gone gets a fresh worker."""
        link = self.link
        if self._closed or (link is not None and link.alive):
            self.call(m.Reset(), "reset")
            return self.view
        self._published, self._launched = None, False
        self.history = self._new_history()
        init = m.RunInit(self.id, self.limits, spec=self.spec, message="reset", created_at=self.created_at,
                         persist=self.store is not None, first_save=True, hooks=self.hooks)  # fmt: skip
        view = self.launch(init)
        self.events.add(0, 0, "status", "reset, in a fresh worker")
        return view

    def step(self, steps: int) -> RunView:
        self.call(m.Step(steps), "step")
        return self.view

    def patch(self, *, set_hz: bool = False, hz: float | None = None,
              behaviour: BehaviourSpec | None = None) -> RunView:  # fmt: skip
        """Change the speed (when `set_hz`; None is full speed) and/or the behaviour policy."""
        self.call(m.Patch(set_hz, hz, behaviour), "change")
        return self.view

    def add_demon(self, demon: DemonSpec) -> RunView:
        self.call(m.AddDemon(demon), "add demons to")
        return self.view

    def remove_demon(self, name: str) -> RunView:
        self.call(m.RemoveDemon(name), "remove demons from")
        return self.view

    def snapshot(self) -> bytes:
        """The run's snapshot document, as JSON bytes."""
        data: bytes = self.call(m.Export(), "export")
        return data

    def value_map(self, demon: str, resolution: int) -> Any:
        return self.call(m.ValueMapOf(demon, resolution), "read the value map of")

    def greedy_actions(self, demon: str, resolution: int) -> np.ndarray | None:
        result: np.ndarray | None = self.call(m.GreedyOf(demon, resolution), "read the greedy actions of")
        return result

    def phase(self, demon: str, x: str, y: str, resolution: int) -> Any:
        return self.call(m.PhaseOf(demon, x, y, resolution), "read the phase plane of")

    def star(self, demon: str) -> np.ndarray:
        values: np.ndarray = self.call(m.StarOf(demon), "read the star of")
        return values

    def state_values(self, demon: str) -> dict[str, object] | None:
        """The demon's value at every state of a chain (or Baird's star) beside the truth; None elsewhere."""
        report: dict[str, object] | None = self.call(m.StateValuesOf(demon), "read the state values of")
        return report

    def evaluate(self, command: m.Evaluate, abandoned: Callable[[], bool]) -> Any:
        return self.call(command, "evaluate", COMMAND_TIMEOUT, abandoned)

    def crash(self, how: m.CrashKind) -> None:
        """Tests only: make the worker crash (or hang), as a crafted input could."""
        link = self._worker("crash")
        link.send(m.Call(0, m.Crash(how)))


def _now(write: Callable[[], float]) -> Future[float]:
    future: Future[float] = Future()
    try:
        future.set_result(write())
    except Exception as exc:
        future.set_exception(exc)
    return future
