"""A live run in its worker: the loop that steps its session and answers the commands that reach it.

The worker is one process of this machine (`executor.py`) or a Ray actor (`ray_host.py`); either way its
main loop runs here, over a `Channel` to the API process. It builds the run (a fresh simulation, a stored
snapshot or an imported one), says `Ready` with its first update (and a new run's first save), then:

- at full speed (hz = None) learns in chunks of about CHUNK_SECONDS and looks at its channel between them;
  with `hz` it paces its steps and waits on the channel in between, so a command is answered at once;
- answers each `Call` with a `Reply`: the session's rule (`RunSession`), then a save and a publication that
  travel with the reply; value maps, greedy actions, phase planes and Baird's star are read between chunks;
  a Monte-Carlo evaluation runs in a thread of its own on a frozen copy of the weights;
- publishes `Update`s as it learns (`Recorder`), and a `Beat` every BEAT_SECONDS from a thread of its own,
  whose progress counter stops when the main loop is stuck.

A live run is the first trial of its protocol: it is seeded as `run_trial(spec, 0)` is and runs the same
episode loop. The loop never dies of bad input or a numerical accident: an exception while learning marks the
run `failed` with the exception's message. It ends at `Shutdown` (the run saved, a running one as paused) or
when the API process has gone (its channel closed).
"""

from __future__ import annotations

import contextlib
import logging
import os
import pickle
import threading
import time
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np
from pydantic import ValidationError

from horde.core import threads
from horde.core.world import WorldState
from horde.runs import messages as m
from horde.runs.collector import keep_out_of_collector
from horde.runs.errors import ConflictError, SpecError
from horde.runs.readout import state_values, value_map
from horde.runs.recorder import Recorder
from horde.runs.run_setup import check_limits, new_simulation
from horde.runs.session import RunSession, Source, kernels_ready
from horde.runs.snapshot import Snapshot, capture, from_bytes, restore
from horde.runs.weights import Readable, Reader, evaluate_in_thread, greedy_actions, phase_values, star_values
from horde.runs.worker_life import Channel, GoneError, Heart, crash
from horde.spec import RunSpec

log = logging.getLogger(__name__)

CHUNK_SECONDS = 0.02  # full speed: learn this long between looks at the channel
MAX_LAG = 0.1  # hz pacing: time lost beyond this is not caught up
MAX_WAIT = 1.0  # hz pacing and idle: the longest single wait for a message (then the loop turns again)
READ_COPY_SECONDS = 0.5  # while a run runs, its readouts share one copy of its weights at most this old


def _build(init: m.RunInit) -> tuple[Source, RunSpec, Any]:
    """The run's source and spec, from a spec (given, or validated here from data), a stored snapshot or an
    imported one (then its stop reference).

    Raises:
        SpecError: the data does not validate (located under `init.loc`), or the spec is larger than the server's
            limits, or cannot run.
    """
    if init.data is not None:
        try:
            spec = RunSpec.model_validate(init.data)
        except ValidationError as exc:
            raise SpecError.from_validation(exc, init.loc) from None
        check_limits(spec, init.limits)
        sim = new_simulation(spec)
        return sim, sim.spec, None  # a Gymnasium world's sensors resolved by its simulation (the API reads them)
    if init.spec is not None:
        sim = new_simulation(init.spec)
        return sim, sim.spec, None
    snapshot: Snapshot = init.snapshot if init.snapshot is not None else from_bytes(init.stored or b"")
    restored = restore(snapshot)
    return restored.sim, restored.sim.spec, restored.stop_reference


class RunWorker:
    """One live run and its loop.

    Args:
        channel: the connection to the API process.
        init: what to build, and the run's state.
        node: where this worker runs, for `Ready` (a Ray node's id; empty for a local process).
    """

    def __init__(self, channel: Channel, init: m.RunInit, node: str = "") -> None:
        self.channel = channel
        self.init = init
        self.node = node
        self._turns = 0
        self._next_step_at = 0.0
        self._cancels: dict[int, threading.Event] = {}
        self._copy: tuple[tuple[int, int, int], float, Readable] | None = None  # (key, fresh until, weights)
        self._handlers: dict[type, Callable[[Any], Any]] = {
            m.Start: self._start, m.Pause: self._pause, m.Reset: self._reset, m.Step: self._step,
            m.Patch: self._patch, m.AddDemon: self._add_demon, m.RemoveDemon: self._remove_demon,
            m.Export: self._export, m.Crash: self._crash,
        }  # fmt: skip
        # Readouts: worked out in the reader's thread on a copy of the weights, while the loop learns on.
        self._readouts: dict[type, Callable[[Any, Readable], Any]] = {
            m.ValueMapOf: lambda c, w: value_map(w, c.demon, c.resolution),
            m.GreedyOf: lambda c, w: greedy_actions(w, c.demon, c.resolution),
            m.StarOf: lambda c, w: star_values(w, c.demon),
            m.StateValuesOf: lambda c, w: state_values(w, c.demon),
        }
        self._reader = Reader(self._reply_from_thread)

    # ------------------------------------------------------------------------------------------
    # Life

    def serve(self) -> None:
        """Build the run, say Ready, and run the loop until Shutdown or the API process has gone."""
        init = self.init
        if init.threads is not None:
            threads.set_budget(init.threads)
        self.heart = Heart(self.channel, lambda: self._turns + self._steps())
        self.heart.busy("building the run")
        try:
            sim, spec, reference = _build(init)
        except Exception as exc:
            self.channel.send(m.Ready(failure=m.failure_of(exc), pid=os.getpid(), node=self.node))
            self.heart.stop()
            return
        if init.resumed:
            where = "its latest snapshot" if init.spec is None else "its start (no snapshot had been saved)"
            init = self.init = replace(init, message=f"running again from step {sim.total_steps}, {where}, after a "
                                                     "restart")  # fmt: skip
        self.session = RunSession(sim, init.limits, status=init.status, hz=init.hz, message=init.message,
                                  summary=init.summary, stop_reference=reference)  # fmt: skip
        self.session.spec = spec
        self.recorder = Recorder(init.run_id, init.limits, self.channel.send, init.created_at, sim.horde.names,
                                 init.persist, spec)  # fmt: skip
        self.session.recorder = self.recorder
        keep_out_of_collector()
        # A new run is saved before it is listed: its row, and an imported run's snapshot (a fresh one is its spec
        # and seed until it learns: a 9,000-demon snapshot would cost seconds to encode for nothing).
        first_save = self.recorder.save(self.session, snapshot=init.snapshot is not None) if init.first_save else None
        self.heart.idle()
        # The spec as built goes back when the API has none, or has a Gymnasium world's without its sensors resolved
        # (they are resolved here, where the environment is made).
        unresolved = spec.world.kind == "gymnasium"
        built = pickle.dumps(spec, protocol=pickle.HIGHEST_PROTOCOL) if init.data is not None or unresolved else None
        ready = m.Ready(
            self.recorder.take_update(self.session), first_save, pid=os.getpid(), node=self.node, spec=built
        )
        self.channel.send(ready)
        try:
            self._loop()
        except GoneError:
            log.info("run %s: the API process has gone; the worker ends", init.run_id)
        finally:
            self.heart.stop()

    def _steps(self) -> int:
        session = getattr(self, "session", None)
        return session.sim.total_steps if session is not None else 0

    def _loop(self) -> None:
        while True:
            self._turns += 1
            try:
                if self.session.status != "running":
                    self._answer(self._next(MAX_WAIT))
                elif self.session.hz is None:
                    self._run_chunk()
                else:
                    self._run_paced()
            except _ShutdownError:
                return
            except GoneError:
                raise
            except Exception as exc:  # the loop never dies
                self.session.fail(exc)

    def _learn(self, steps: int | None, deadline: float | None) -> None:
        """The session's learning; while the kernels are first compiled (or loaded) the heartbeat says so."""
        compiling = not kernels_ready()
        if compiling:
            self.heart.busy(m.COMPILING)
        try:
            self.session.learn(steps, deadline)
        finally:
            if compiling:
                self.heart.idle()

    def _run_chunk(self) -> None:
        """Full speed: messages first, then about CHUNK_SECONDS of learning."""
        self._drain()
        session = self.session
        if session.status != "running" or session.hz is not None:
            return
        self._learn(None, time.monotonic() + CHUNK_SECONDS)
        self.recorder.publish(session, force=False)
        self.recorder.maybe_snapshot(session)

    def _run_paced(self) -> None:
        """hz pacing: wait for the next step's time (answering messages meanwhile), then step."""
        wait = self._next_step_at - time.monotonic()
        if wait > 0:
            call = self._next(min(wait, MAX_WAIT))
            if call is not None:
                self._answer(call)
                return
            if wait > MAX_WAIT:
                return  # not due yet: look at the channel again
        self._drain()
        session = self.session
        if session.status != "running" or session.hz is None:
            return
        hz = session.hz
        now = time.monotonic()
        due = min(1 + int((now - self._next_step_at) * hz), max(1, int(hz * CHUNK_SECONDS)))
        self._learn(due, None)
        self._next_step_at = max(self._next_step_at + due / hz, now - MAX_LAG)
        self.recorder.publish(session, force=False)
        self.recorder.maybe_snapshot(session)

    # ------------------------------------------------------------------------------------------
    # Messages

    def _next(self, timeout: float | None) -> m.Call | None:
        """The next call within `timeout` seconds; the other messages are handled on the way."""
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            left = None if deadline is None else max(0.0, deadline - time.monotonic())
            if not self.channel.poll(left):
                return None
            try:
                message = self.channel.recv()
            except (EOFError, OSError):
                raise GoneError from None
            if isinstance(message, m.Call):
                return message
            self._note(message)

    def _drain(self) -> None:
        while (call := self._next(0.0)) is not None:
            self._answer(call)

    def _note(self, message: m.ToWorker) -> None:
        if isinstance(message, m.SaveDone):
            self.recorder.saved(message)
        elif isinstance(message, m.Cancel):
            cancel = self._cancels.get(message.cid)
            if cancel is not None:
                cancel.set()
        elif isinstance(message, m.SetThreads):
            threads.set_budget(message.count)

    def _answer(self, call: m.Call | None) -> None:
        """Run one call and send its reply (with the save and the update it made, if any)."""
        if call is None:
            return
        command = call.command
        if isinstance(command, m.Shutdown):
            self._shutdown(call.cid, command.save)
        if isinstance(command, m.Evaluate):  # in a thread of its own, on a frozen copy of the weights
            self._cancels[call.cid] = cancel = threading.Event()
            evaluate_in_thread(self._weights(), call.cid, command, cancel, self._reply_from_thread)
            return
        readout = self._readouts.get(type(command))
        if isinstance(command, m.PhaseOf):  # the other sensors held at the agent's readings now
            held = np.array(self.session.sim.sensors, dtype=float, copy=True)
            readout = lambda c, w: phase_values(w, held, c.demon, c.x, c.y, c.resolution)  # noqa: E731
        if readout is not None:
            weights = self._weights()
            self._reader.submit(call.cid, lambda: readout(command, weights))
            return
        self.heart.busy(type(command).__name__)
        self._save: m.Save | None = None
        self._update: m.Update | None = None
        try:
            value = self._handlers[type(command)](command)
        except Exception as exc:
            reply = m.Reply(call.cid, failure=m.failure_of(exc), update=self._update, save=self._save)
        else:
            reply = m.Reply(call.cid, value, update=self._update, save=self._save)
        finally:
            self.heart.idle()
        self.channel.send(reply)

    def _commit(self, rule: Callable[[], None], snapshot: bool = True) -> None:
        """A command's rule, then its save and its publication (sent with the reply, even when the rule failed
        halfway: what it changed is saved and shown)."""
        try:
            rule()
        finally:
            self._save = self.recorder.save(self.session, snapshot)
            self._update = self.recorder.take_update(self.session)

    # ------------------------------------------------------------------------------------------
    # Commands

    def _start(self, _: m.Start) -> None:
        def rule() -> None:
            self.session.start()
            self._next_step_at = time.monotonic()

        self._commit(rule, snapshot=False)

    def _pause(self, _: m.Pause) -> None:
        self._commit(self.session.pause)

    def _reset(self, _: m.Reset) -> None:
        self._commit(self.session.reset)

    def _step(self, command: m.Step) -> None:
        session = self.session
        try:
            session.step(command.steps)
        finally:
            if session.status == "paused":  # a finished run saved itself when it finished
                self._save = self.recorder.save(session, snapshot=True)
            self._update = self.recorder.take_update(session)

    def _patch(self, command: m.Patch) -> None:
        def rule() -> None:
            self.session.patch(command.set_hz, command.hz, command.behaviour)
            if command.set_hz:
                self._next_step_at = time.monotonic()

        self._commit(rule)

    def _add_demon(self, command: m.AddDemon) -> None:
        self._commit(lambda: self.session.add_demon(command.demon))

    def _remove_demon(self, command: m.RemoveDemon) -> None:
        self._commit(lambda: self.session.remove_demon(command.name, self.init.run_id))

    def _export(self, _: m.Export) -> bytes:
        session = self.session
        snapshot = capture(session.sim, session.spec, session.status, session.hz, session.stop_reference)
        return snapshot.model_dump_json(by_alias=True).encode()

    def _crash(self, command: m.Crash) -> None:
        if not self.init.hooks:
            raise ConflictError("this worker was not started with test hooks")
        self.heart.busy(f"crash {command.how}")
        crash(command.how)

    def _weights(self) -> Readable:
        """The run's weights for a readout: a copy (`Simulation.view_state`, the primary weights only) that every
        readout shares while the run has not stepped, or, while it runs, for at most READ_COPY_SECONDS (or 20
        times what the copy took: for nexting's 10 M weights a copy costs tens of milliseconds, and the live
        view asks for value maps several times a second). An evaluation's thread reads the same copy: nothing
        changes it after it is made."""
        sim = self.session.sim
        key = (id(sim), sim.total_steps, id(self.session.spec))
        now = time.monotonic()
        cached = self._copy
        if cached is not None and (cached[0] == key or (self.session.status == "running" and cached[0][:1] == key[:1]
                                                         and now < cached[1])):  # fmt: skip
            return cached[2]
        began = time.thread_time()
        world = sim.world_state
        if isinstance(world, WorldState):
            world = WorldState(*(np.array(a, copy=True) for a in world))
        weights = Readable(self.init.run_id, self.session.spec, sim.horde, sim.view_state(), world, sim.total_steps)
        cost = time.thread_time() - began
        self._copy = (key, now + max(READ_COPY_SECONDS, 20 * cost), weights)
        return weights

    def _reply_from_thread(self, reply: m.Reply) -> None:
        self._cancels.pop(reply.cid, None)
        with contextlib.suppress(Exception):  # the channel closed: the worker is ending
            self.channel.send(reply)

    def _shutdown(self, cid: int, save_it: bool) -> None:
        """Save the run (a running one as paused) unless it is being deleted, answer, and leave the loop."""
        session = self.session
        failure = None
        save = None
        if save_it:
            if session.status == "running":
                session.set_status("paused", f"paused at step {session.sim.total_steps} when the server stopped")
            self.recorder.wait_encoded()
            try:
                save = self.recorder.save(session, snapshot=session.status != "failed")
            except Exception as exc:
                failure = m.failure_of(exc)
        self.channel.send(m.Reply(cid, None, failure, self.recorder.take_update(session), save))
        raise _ShutdownError


class _ShutdownError(Exception):
    """Leaves the main loop after Shutdown was answered."""


def serve_run(channel: Channel) -> None:
    """A live run's worker (the fork server's entry): its first message is its `RunInit`."""
    init = channel.recv()
    assert isinstance(init, m.RunInit)
    RunWorker(channel, init).serve()
