"""One live run: its simulation, owned by one learner thread, and the commands that reach it.

Only the learner thread touches the simulation. Other threads talk to it in two ways:

- commands (start, pause, step, add a demon, export a snapshot, ...) go through a queue and come
  back as a result or an exception through a `Future`; the thread runs them between chunks of steps;
- readers take `view`, an immutable `RunView` that the thread publishes after every chunk.

At full speed (hz = None) the thread learns in chunks of about 20 ms and looks at its queue between
them; with `hz` it paces its steps and waits on the queue in between, so a command is answered at once.
A live run is the first trial of its protocol: it is seeded as `run_trial(spec, 0)` is and runs the same
episode loop, and it finishes when the protocol's episodes are done (or its stopping rule fires);
with `protocol.episodes = 0` it runs until paused. The learner thread never dies of bad input or a
numerical accident: an exception while learning marks the run `failed` with the exception's message.

Why one module of about 700 lines: the generic part, the command queue, lives in `commands.py` and the
protocol's stopping rule in `core.experiment`; what stays here (pacing, the status rules, dependency
checks, saving and publishing) all reads and writes the learner thread's own state between two chunks
of steps. Splitting it into a run session and a recorder (REVIEW item 6) is left until a second kind of
run shows what the two would share.
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import threading
import time
from collections.abc import Callable
from concurrent.futures import Future
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np
from pydantic import ValidationError

from horde.core.experiment import start_point, stopping_rule
from horde.core.fast import FOREVER
from horde.core.simulation import Simulation
from horde.core.world import WorldState
from horde.runs.commands import CommandQueue, ShutdownError
from horde.runs.divergence import MAX_MAGNITUDE, beyond_magnitude
from horde.runs.errors import BusyError, ConflictError, NotFoundError, SaveError, SpecError
from horde.runs.events import EventLog
from horde.runs.history import History
from horde.runs.run_setup import MAX_HZ, MIN_HZ, Limits, check_limits, new_simulation
from horde.runs.run_view import RunStatus, RunView, Summary
from horde.runs.saver import Saver
from horde.runs.snapshot import Snapshot, capture, encode_frozen, freeze, to_bytes
from horde.runs.store import RunRecord, Store
from horde.spec import BehaviourSpec, DemonSpec, RunSpec, demon_dependencies

log = logging.getLogger(__name__)

T = TypeVar("T")

CHUNK_SECONDS = 0.02  # full speed: learn this long between looks at the command queue
# One call into the simulation takes about this long. The compiled loop holds the GIL for a whole call,
# so this bounds how long the server's event loop (requests, streams) can wait for it.
BATCH_SECONDS = 0.002
MAX_BATCH = 100_000
PUBLISH_INTERVAL = 1.0 / 60.0  # while running, views are published at most this often
MAX_PUBLISH_INTERVAL = 0.5  # ... and at least this often, however long a view takes to make
# Every weight is scanned for MAX_MAGNITUDE at most this often (62 ms for nexting's 2 x 10 M weights); the
# engine checks every demon's TD error, prediction and action values at every step.
WEIGHT_SCAN_INTERVAL = 1.0
MAX_LAG = 0.1  # hz pacing: time lost beyond this is not caught up
MAX_WAIT = 1.0  # hz pacing: the longest single wait for the next step (then the loop looks again)
COMMAND_TIMEOUT = 600.0  # a command waits this long for the learner thread at most
# The compiled kernels are compiled (or loaded from numba's cache) at their first call in a process; until
# that call returns, a run says so instead of standing at step 0 without a word.
PREPARING = "preparing the learning kernels (compiling them takes about a minute on a machine's first run)"
_kernels_ready = threading.Event()
NOT_SAVED = "; not saved: "  # what a run's message adds when its latest waited save failed


@dataclass(frozen=True)
class SnapshotCost:
    """What the latest snapshot cost: freezing it in the learner thread, encoding and writing it after."""

    freeze_seconds: float = 0.0
    encode_seconds: float = 0.0
    write_seconds: float = 0.0
    bytes: int = 0


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
        sim: the simulation (fresh, or restored from a snapshot); its spec is the run's spec.
        limits: the server's size limits and timings.
        store: where the run saves itself (None: nowhere).
        status, hz, message, created_at, summary: the run's state when it is restored.
        stop_reference: the stopping rule's reference weights (default: the current weights).
        saver: the writer thread that periodic snapshots are handed to (None: written in this thread).
    """

    def __init__(
        self,
        run_id: str,
        sim: Simulation,
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
        self._saver = saver
        self._pending_save: Future[Any] | None = None  # the periodic snapshot being written
        self.snapshot_cost = SnapshotCost()
        self._diverged: set[str] = set()  # demons reported diverged in the events
        self.limits = limits
        self._store = store
        self._sim = sim
        self._spec = sim.spec
        self._status: RunStatus = status
        self._hz = hz
        self._message = message
        self._created_at = created_at if created_at is not None else time.time()
        self._summary = summary
        self._stop_reference = stop_reference if stop_reference is not None else self._thetas()
        self.history = History(sim.horde.names, limits.history, limits.history_every)
        self.events = EventLog(limits.events)
        self._commands = CommandQueue(f"run {run_id!r}")
        self._thread = threading.Thread(target=self._loop, name=f"horde-run-{run_id}", daemon=True)
        self._seq = 0
        self._batch = 1
        self._last_row = -FOREVER  # no row yet
        self._next_row = 0.0
        self._next_publish = 0.0
        self._next_weight_scan = 0.0
        self._last_snapshot = time.monotonic()
        self._next_step_at = 0.0
        if status == "finished" and summary is None:
            self._summary = self._summarize(stopped_early=False)
        self.view = self._make_view()

    # ------------------------------------------------------------------------------------------
    # Life cycle (called from other threads)

    def start_thread(self) -> None:
        self._thread.start()

    def save(self) -> None:
        """Write the run and a snapshot to the store; only before `start_thread`.

        Raises:
            SaveError: the store refused the write.
        """
        self._persist(snapshot=True)

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
    # Commands (each runs in the learner thread through `call`)

    def start(self) -> RunView:
        return self.call(self._do_start)

    def pause(self) -> RunView:
        return self.call(self._do_pause)

    def reset(self) -> RunView:
        return self.call(self._do_reset)

    def step(self, steps: int) -> RunView:
        return self.call(lambda: self._do_step(steps))

    def patch(
        self, *, set_hz: bool = False, hz: float | None = None, behaviour: BehaviourSpec | None = None
    ) -> RunView:
        """Change the speed (when `set_hz`; None is full speed) and/or the behaviour policy."""
        return self.call(lambda: self._do_patch(set_hz, hz, behaviour))

    def add_demon(self, demon: DemonSpec) -> RunView:
        return self.call(lambda: self._do_add_demon(demon))

    def remove_demon(self, name: str) -> RunView:
        return self.call(lambda: self._do_remove_demon(name))

    def snapshot(self) -> Snapshot:
        return self.call(self._capture)

    # ------------------------------------------------------------------------------------------
    # The learner thread

    def _loop(self) -> None:
        _lower_priority()
        while True:
            try:
                if self._status != "running":
                    command = self._commands.next()
                    if command is not None:
                        self._commands.run(command)
                elif self._hz is None:
                    self._run_chunk()
                else:
                    self._run_paced()
            except ShutdownError:
                return
            except Exception as exc:  # the learner thread never dies
                self._fail(exc)

    def _run_chunk(self) -> None:
        """Full speed: commands first, then about CHUNK_SECONDS of learning."""
        self._commands.drain()
        if self._status != "running" or self._hz is not None:
            return
        self._learn(None, time.monotonic() + CHUNK_SECONDS)
        self._publish(force=False)
        self._maybe_snapshot()

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
        if self._status != "running" or self._hz is None:
            return
        hz = self._hz
        now = time.monotonic()
        due = min(1 + int((now - self._next_step_at) * hz), max(1, int(hz * CHUNK_SECONDS)))
        self._learn(due, None)
        self._next_step_at = max(self._next_step_at + due / hz, now - MAX_LAG)
        self._publish(force=False)
        self._maybe_snapshot()

    def _learn(self, steps: int | None, deadline: float | None) -> None:
        """Take `steps` steps, or step until `deadline`, or until the run finishes; a failure marks it failed.

        Steps go in batches (`Simulation.run`) that end at every episode end, so the protocol's episode
        loop sees each episode as `run_trial` does; batches are sized to take about BATCH_SECONDS. A
        history row is taken after a batch when `history.every` steps and `limits.history_interval`
        seconds have passed since the last row: every step of a run paced by hz (up to 1/interval
        steps per second), a sample of a run at full speed.
        """
        sim = self._sim
        behaviour = self._spec.behaviour
        done = 0
        # Said while running; a step command's caller waits for its answer anyway.
        preparing = not _kernels_ready.is_set() and self._status == "running"
        if preparing:
            # What the run said before (say, where it came back from after a restart) stays readable.
            told = self._message
            self._message = PREPARING if told in ("", "running") else f"{PREPARING}; {told}"
            self._publish()
        try:
            while True:
                batch = self._batch if steps is None else min(self._batch, steps - done)
                episode, before = sim.episode, sim.total_steps
                began = time.perf_counter()
                sim.run(batch, 1, behaviour)
                if preparing:
                    _kernels_ready.set()
                    preparing = False
                    if self._message.startswith(PREPARING):
                        self._message = told
                taken = sim.total_steps - before
                self._adapt_batch(taken, time.perf_counter() - began)
                done += taken
                if sim.total_steps - self._last_row >= self.history.every and time.monotonic() >= self._next_row:
                    self._record()
                if sim.episode != episode:
                    self._episode_ended()
                    if self._status == "finished":
                        return
                if steps is not None and done >= steps:
                    return
                if deadline is not None and time.monotonic() >= deadline:
                    return
        except Exception as exc:
            self._fail(exc)

    def _adapt_batch(self, taken: int, seconds: float) -> None:
        if taken > 0 and seconds > 0.0:
            self._batch = max(1, min(MAX_BATCH, int(taken / seconds * BATCH_SECONDS)))

    def _record(self) -> None:
        sim = self._sim
        out = sim.readout()  # O(D): no weights are copied
        self.history.record(sim.total_steps, out.prediction, out.cumulant, out.delta, out.rupee, out.ude)
        self._last_row = sim.total_steps
        self._next_row = time.monotonic() + self.limits.history_interval

    def _episode_ended(self) -> None:
        """The protocol's episode loop, as `run_trial` runs it: the stopping rule, then the episode count."""
        sim = self._sim
        self.events.add(
            sim.total_steps,
            sim.episode,
            "episode",
            f"episode {sim.episode} ended, return {sim.last_return:.4g}",
            sim.last_return,
        )
        protocol = self._spec.protocol
        if protocol.episodes == 0:
            return
        done = sim.episode
        stopped, self._stop_reference = stopping_rule(protocol.stop, done, self._thetas, self._stop_reference)
        if stopped:
            self._finish(stopped_early=True)
            return
        if done >= protocol.episodes:
            self._finish(stopped_early=False)

    def _thetas(self) -> list[np.ndarray]:
        return self._sim.thetas()

    def _summarize(self, stopped_early: bool) -> Summary:
        sim = self._sim
        hs, horde = sim.horde_state, sim.horde
        diverged = dict(zip(horde.names, hs.diverged.tolist(), strict=True))
        predictions = sim.predictions_at(*start_point(self._spec))
        return Summary(
            predictions={name: math.nan if diverged[name] else value for name, value in predictions.items()},
            rupee=dict(zip(horde.names, horde.rupee(hs).tolist(), strict=True)),
            ude=dict(zip(horde.names, horde.ude(hs).tolist(), strict=True)),
            episodes=sim.episode,
            steps=sim.total_steps,
            last_return=sim.last_return,
            stopped_early=stopped_early,
        )

    def _finish(self, stopped_early: bool) -> None:
        self._summary = self._summarize(stopped_early)
        reason = "the stopping rule fired" if stopped_early else "its episodes are done"
        self._set_status("finished", f"finished after {self._sim.episode} episodes: {reason}")
        with contextlib.suppress(SaveError):  # no caller to raise it to: the message and the events say it
            self._persist(snapshot=True)

    def _fail(self, exc: Exception) -> None:
        log.error("run %s failed", self.id, exc_info=exc)
        self._set_status("failed", f"{type(exc).__name__}: {exc}", kind="error")
        with contextlib.suppress(SaveError):  # said in the message and the events
            self._persist(snapshot=False)
        self._publish()

    def _set_status(self, status: RunStatus, message: str = "", kind: str = "status") -> None:
        self._status = status
        self._message = message
        sim = self._sim
        self.events.add(sim.total_steps, sim.episode, "error" if kind == "error" else "status", message or status)

    def _require(self, allowed: tuple[RunStatus, ...], action: str) -> None:
        if self._status not in allowed:
            hint = {
                "running": "pause it first",
                "finished": "reset it to run again",
                "failed": f"it failed ({self._message}); reset it",
            }.get(self._status, "")
            raise ConflictError(f"cannot {action} a {self._status} run" + (f": {hint}" if hint else ""))

    def _do_start(self) -> RunView:
        self._require(("created", "paused"), "start")
        self._set_status("running", "running")
        self._next_step_at = time.monotonic()
        return self._commit(snapshot=False)

    def _do_pause(self) -> RunView:
        self._require(("running",), "pause")
        if self._last_row < self._sim.total_steps:  # the history (and its charts) ends where the run stands
            self._record()
        self._set_status("paused", f"paused at step {self._sim.total_steps}")
        return self._commit(snapshot=True)

    def _do_reset(self) -> RunView:
        self._sim = new_simulation(self._spec)
        self._last_row = -FOREVER  # no row yet
        self._summary = None
        self._stop_reference = self._thetas()
        self.history = History(self._sim.horde.names, self.limits.history, self.limits.history_every)
        self._set_status("created", "reset")
        return self._commit(snapshot=True)

    def _do_step(self, steps: int) -> RunView:
        self._require(("created", "paused"), "step")
        if self._status == "created":
            self._set_status("paused", "stepped")
        self._learn(min(steps, self.limits.max_step_request), None)
        if self._status == "paused":  # a finished run saved itself in `_finish`
            return self._commit(snapshot=True)
        return self._publish()

    def _do_patch(self, set_hz: bool, hz: float | None, behaviour: BehaviourSpec | None) -> RunView:
        if behaviour is not None:
            spec = self._respec(behaviour=behaviour.model_dump(by_alias=True))
            self._spec = spec
            self._sim.spec = spec
        if set_hz:
            if hz is not None and not MIN_HZ <= hz <= MAX_HZ:
                raise SpecError.at(("body", "hz"), f"hz must lie in [{MIN_HZ}, {MAX_HZ:g}] (or be null)")
            self._hz = hz
            self._next_step_at = time.monotonic()
        return self._commit(snapshot=True)

    def _do_add_demon(self, demon: DemonSpec) -> RunView:
        self._require(("created", "running", "paused"), "add demons to")
        if demon.name in self._sim.horde.index:
            raise ConflictError(f"the run already has a demon {demon.name!r}")
        demons = [d.model_dump(by_alias=True) for d in self._spec.demons] + [demon.model_dump(by_alias=True)]
        spec = self._respec(demons=demons)
        check_limits(spec, self.limits)
        return self._swap_horde(spec, f"demon {demon.name!r} joined")

    def _do_remove_demon(self, name: str) -> RunView:
        if name not in self._sim.horde.index:
            raise NotFoundError(f"run {self.id!r} has no demon {name!r}")
        self._require(("created", "running", "paused"), "remove demons from")
        readers = sorted(
            d.name for d in self._spec.demons if d.name != name and name in demon_dependencies(d, self._spec.features)
        )
        if readers:
            raise ConflictError(
                f"cannot remove demon {name!r}: {', '.join(repr(r) for r in readers)} read its prediction or "
                "policy; remove those first"
            )
        if self._spec.behaviour.demon == name:
            raise ConflictError(f"cannot remove demon {name!r}: the behaviour policy acts on it")
        demons = [d.model_dump(by_alias=True) for d in self._spec.demons if d.name != name]
        try:
            spec = self._respec(demons=demons)
        except SpecError as exc:
            raise ConflictError(f"cannot remove demon {name!r}: {exc.problems[0].msg}") from None
        return self._swap_horde(spec, f"demon {name!r} left")

    def _respec(self, **changes: Any) -> RunSpec:
        """The current spec with some top-level fields replaced, validated again."""
        data = self._spec.model_dump(by_alias=True)
        data.update(changes)
        try:
            return RunSpec.model_validate(data)
        except ValidationError as exc:
            raise SpecError.from_validation(exc, ("body",)) from None

    def _swap_horde(self, spec: RunSpec, message: str) -> RunView:
        """A new Horde for a changed set of demons, keeping every remaining demon's weights."""
        sim = self._sim = self._sim.with_spec(spec)
        self._spec = spec
        self.history = self.history.remap(sim.horde.names)
        self._stop_reference = self._thetas()
        self.events.add(sim.total_steps, sim.episode, "demon", message)
        return self._commit(snapshot=True)

    def _capture(self) -> Snapshot:
        return capture(self._sim, self._spec, self._status, self._hz, self._stop_reference)

    def _shutdown(self) -> None:
        """Save the run (a running one as paused), refuse further commands, and leave the loop."""
        if self._status == "running":
            self._set_status("paused", f"paused at step {self._sim.total_steps} when the server stopped")
        failure: SaveError | None = None
        try:
            self._persist(snapshot=self._status != "failed")
        except SaveError as exc:
            failure = exc
        self._publish()
        self._commands.close()
        raise ShutdownError(failure)

    # ------------------------------------------------------------------------------------------
    # Publication and persistence

    def _mark_diverged(self) -> None:
        """Report the demons the engine froze; freeze those with a weight beyond MAX_MAGNITUDE (scanned at most
        every WEIGHT_SCAN_INTERVAL: the engine's own per-step check reads predictions, not every weight)."""
        sim = self._sim
        state = sim.horde_state
        diverged = state.diverged  # [D]
        now = time.monotonic()
        if now >= self._next_weight_scan:
            self._next_weight_scan = now + WEIGHT_SCAN_INTERVAL
            beyond = beyond_magnitude(sim.horde, state) & ~state.diverged  # [D]
            if beyond.any():
                sim.horde_state = state._replace(diverged=state.diverged | beyond)
            diverged = state.diverged | beyond  # [D]
        for i in np.nonzero(diverged)[0]:
            name = sim.horde.names[i]
            if name not in self._diverged:
                self._diverged.add(name)
                self.events.add(
                    sim.total_steps,
                    sim.episode,
                    "error",
                    f"demon {name!r} diverged: its numbers went beyond {MAX_MAGNITUDE:g} or non-finite; it is frozen",
                )

    def _make_view(self) -> RunView:
        self._mark_diverged()
        sim = self._sim
        self._seq += 1
        return RunView(
            id=self.id,
            status=self._status,
            message=self._message,
            hz=self._hz,
            spec=self._spec,
            horde=sim.horde,
            horde_state=sim.view_state(),  # a copy of what readers need: the learner never changes it
            rupee=(out := sim.readout()).rupee,
            ude=out.ude,
            world_state=WorldState(*(np.array(a, copy=True) for a in sim.world_state)),
            episode=sim.episode,
            total_steps=sim.total_steps,
            episode_return=sim.episode_return,
            last_return=sim.last_return,
            created_at=self._created_at,
            updated_at=time.time(),
            summary=self._summary,
            seq=self._seq,
            step_size=sim.effective_step_sizes(),
        )

    def _publish(self, force: bool = True) -> RunView:
        """Make the current state visible to readers (while running: at most every PUBLISH_INTERVAL)."""
        began = time.monotonic()
        if force or began >= self._next_publish or self._status != self.view.status:
            cpu = time.thread_time()
            self.view = self._make_view()
            # Copying a large Horde takes time: keep it under about 5 % of the learner thread's. The cost is
            # this thread's CPU time, not wall time, so a stall elsewhere (the event loop holding the GIL)
            # cannot stretch the interval; and it is capped, so readers never wait long for a fresh view.
            cost = time.thread_time() - cpu
            self._next_publish = began + min(MAX_PUBLISH_INTERVAL, max(PUBLISH_INTERVAL, 20 * cost))
        return self.view

    def _maybe_snapshot(self) -> None:
        """A periodic snapshot of a running run, handed to the writer thread.

        Every `limits.snapshot_every` seconds, or three times the last write's time when that is longer
        (a large Horde's writes then keep the writer busy a third of the time at most); never while the
        previous one is still being written.
        """
        if self._status != "running" or (self._pending_save is not None and not self._pending_save.done()):
            return
        cost = self.snapshot_cost
        interval = max(self.limits.snapshot_every, 3 * (cost.encode_seconds + cost.write_seconds))
        if time.monotonic() - self._last_snapshot >= interval:
            self._persist(snapshot=True, wait=False)

    def _commit(self, snapshot: bool) -> RunView:
        """Save the state a command left (waiting for the write) and publish it.

        Raises:
            SaveError: the write failed; the state is published all the same, its message saying so.
        """
        try:
            self._persist(snapshot)
        finally:
            view = self._publish()
        return view

    def _store_row(self) -> RunRecord:
        """The run's row in the store, as it stands now."""
        sim = self._sim
        return RunRecord(
            id=self.id,
            name=self._spec.name,
            status=self._status,
            message=self._message,
            hz=self._hz,
            spec=self._spec.model_dump_json(by_alias=True),
            episode=sim.episode,
            steps=sim.total_steps,
            created_at=self._created_at,
            updated_at=time.time(),
        )

    def _persist(self, snapshot: bool, wait: bool = True) -> None:
        """Save the run's record (and a snapshot) in one transaction.

        The state is frozen here, in the learner thread; encoding and writing happen in the saver's
        thread when there is one. With `wait` the call returns once the write is done, and a failed
        write raises; without it (the periodic snapshots) a failure is told in the run's events.

        Raises:
            SaveError: with `wait`, the write failed or did not finish within COMMAND_TIMEOUT; the run's
                message and events say so too.
        """
        if snapshot:
            self._last_snapshot = time.monotonic()
        if self._store is None:
            return
        store = self._store
        sim = self._sim
        if wait:  # this save's outcome replaces what the message said of the last one
            self._message = self._message.split(NOT_SAVED)[0]
        try:
            began = time.perf_counter()
            record = self._store_row()
            frozen = freeze(sim, self._spec, self._status, self._hz, self._stop_reference) if snapshot else None
            summary = self._summary.to_json() if self._summary is not None else None
            freeze_seconds = time.perf_counter() - began
        except Exception as exc:
            self._save_failed(exc, wait)
            return

        def write() -> None:
            began = time.perf_counter()
            data = to_bytes(encode_frozen(frozen)) if frozen is not None else None
            encoded = time.perf_counter()
            store.save_run(record, data, summary)
            if data is not None:
                self.snapshot_cost = SnapshotCost(
                    freeze_seconds, encoded - began, time.perf_counter() - encoded, len(data)
                )

        if self._saver is None:
            try:
                write()
            except Exception as exc:
                self._save_failed(exc, wait)
            return
        future = self._saver.submit(write)
        if not wait:
            self._pending_save = future
            future.add_done_callback(self._background_save_done)
            return
        try:
            future.result(COMMAND_TIMEOUT)
        except TimeoutError:
            self._save_failed(TimeoutError(f"the write did not finish within {COMMAND_TIMEOUT:g} s"), wait)
        except Exception as exc:
            self._save_failed(exc, wait)

    def _background_save_done(self, future: Future[Any]) -> None:
        """A periodic snapshot's write ended (in the saver's thread): a failure goes to the events."""
        exc = future.exception()
        if isinstance(exc, Exception):
            self._save_failed(exc, wait=False)

    def _save_failed(self, exc: Exception, wait: bool) -> None:
        """A save failed: the events say so; a waited one (in the learner thread) also the message, and raises.

        Raises:
            SaveError: when `wait`.
        """
        log.error("could not save run %s", self.id, exc_info=exc)
        self.events.add(self._sim.total_steps, self._sim.episode, "error", f"could not save the run: {exc}")
        if wait:
            said = self._message or self._status
            self._message = f"{said}{NOT_SAVED}{exc}"
            raise SaveError(f"run {self.id!r}: {said}, but it could not be saved: {exc}") from exc
