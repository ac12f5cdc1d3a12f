"""A run session: the rules of one live run, over a source of transitions that it steps.

The session is what a live run *is*, apart from its thread and its saving: the source it steps, its spec,
status and message, the protocol's episode loop and stopping rule, divergence, and what each command may
do in each status. It runs in the learner thread only (`LiveRun`), and tells the recorder (`Recorder`)
when a history row, a save or a publication is due, through the few methods of `Recording`.

The source is a `horde.core.source.Source`: the grid world's compiled `Simulation`, or a Gymnasium agent
(`horde.worlds.gym_simulation.GymSimulation`), both over the one engine's `Learner`. `new_source` picks one
for a spec's world kind.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from typing import Any, Protocol

import numpy as np
from pydantic import ValidationError

from horde.core.experiment import stopping_rule
from horde.core.source import Source
from horde.runs.divergence import MAX_MAGNITUDE
from horde.runs.errors import ConflictError, NotFoundError, SpecError
from horde.runs.events import EventLog
from horde.runs.run_setup import Limits, check_limits, new_simulation
from horde.runs.run_view import RunStatus, Summary
from horde.spec import MAX_HZ, MIN_HZ, BehaviourSpec, DemonSpec, RunSpec, demon_dependencies
from horde.worlds.gym_spaces import resolve_world

log = logging.getLogger(__name__)

# One call into the source takes about this long. The compiled loop holds the GIL for a whole call, so this
# bounds how long the server's event loop (requests, streams) can wait for it.
BATCH_SECONDS = 0.002
MAX_BATCH = 100_000
# The compiled kernels are compiled (or loaded from numba's cache) at their first call in a process; until
# that call returns, a run says so instead of standing at step 0 without a word.
PREPARING = "preparing the learning kernels (compiling them takes about a minute on a machine's first run)"
_kernels_ready = threading.Event()


def kernels_ready() -> bool:
    """Whether this process has called the learning kernels once (compiled or loaded them)."""
    return _kernels_ready.is_set()


new_source = new_simulation  # run_setup.new_simulation picks the source for the world's kind


class Recording(Protocol):
    """What a session asks of its recorder (`horde.runs.recorder.Recorder`)."""

    def maybe_record(self, session: RunSession) -> None: ...
    def record(self, session: RunSession, measure: bool = False) -> None: ...
    def measure_end(self, session: RunSession) -> None: ...
    def recorded_to(self) -> int: ...
    def save_quietly(self, session: RunSession, snapshot: bool) -> None: ...
    def publish(self, session: RunSession, force: bool = True) -> Any: ...
    def remap(self, names: list[str]) -> None: ...
    def new_history(self, names: list[str]) -> None: ...


class RunSession:
    """The rules of one run.

    Args:
        sim: the source (fresh, or restored from a snapshot); its spec is the run's spec.
        limits: the server's size limits and timings.
        status, hz, message, summary: the run's state when it is restored.
        stop_reference: the stopping rule's reference weights (default: the current weights).
    """

    def __init__(self, sim: Source, limits: Limits, *, status: RunStatus = "created", hz: float | None = None,
                 message: str = "", summary: Summary | None = None,
                 stop_reference: list[np.ndarray] | None = None) -> None:  # fmt: skip
        self.sim = sim
        self.spec = sim.spec
        self.limits = limits
        self.status: RunStatus = status
        self.hz = hz
        self.message = message
        self.summary = summary
        self.stop_reference = stop_reference if stop_reference is not None else sim.thetas()
        self.events = EventLog(limits.events)
        self.recorder: Recording | None = None
        self._diverged: set[str] = set()  # demons reported diverged in the events
        self._batch = 1
        if status == "finished" and summary is None:
            self.summary = self.summarize(stopped_early=False)

    @property
    def _rec(self) -> Recording:
        assert self.recorder is not None, "a session learns only once its recorder is attached"
        return self.recorder

    # ------------------------------------------------------------------------------------------
    # Stepping

    def learn(self, steps: int | None, deadline: float | None) -> None:
        """Take `steps` steps, or step until `deadline`, or until the run finishes; a failure marks it failed.

        Steps go in batches (`run`) that end at every episode end, so the protocol's episode loop sees each
        episode as `run_trial` does; batches are sized to take about BATCH_SECONDS. The recorder takes a
        history row after a batch when one is due.
        """
        done = 0
        preparing = not _kernels_ready.is_set() and self.status == "running"
        told = self.message
        if preparing:  # what the run said before (say, after a restart) stays readable
            self.message = PREPARING if told in ("", "running") else f"{PREPARING}; {told}"
            self._rec.publish(self)
        try:
            while True:
                batch = self._batch if steps is None else min(self._batch, steps - done)
                if self.paced_for_rows():  # a paced run catching up keeps a history row a step
                    batch = 1
                episode, before = self.sim.episode, self.sim.total_steps
                began = time.thread_time()  # CPU time: a worker preempted mid-batch keeps its batches
                self.sim.run(batch, 1, self.spec.behaviour)
                if preparing:
                    _kernels_ready.set()
                    preparing = False
                    if self.message.startswith(PREPARING):
                        self.message = told
                taken = self.sim.total_steps - before
                self._adapt_batch(taken, time.thread_time() - began)
                done += taken
                self._rec.maybe_record(self)
                if self.sim.episode != episode:
                    self._episode_ended()
                    if self.status == "finished":
                        return
                if (steps is not None and done >= steps) or (deadline is not None and time.monotonic() >= deadline):
                    return
        except Exception as exc:
            self.fail(exc)

    def paced_for_rows(self) -> bool:
        """Paced slowly enough for a history row at every step (then a late worker's catching up steps one at a
        time, each with its row)."""
        return self.hz is not None and self.hz * self.limits.history_interval <= 1.0

    def _adapt_batch(self, taken: int, seconds: float) -> None:
        if taken > 0 and seconds > 0.0:
            self._batch = max(1, min(MAX_BATCH, int(taken / seconds * BATCH_SECONDS)))

    def _episode_ended(self) -> None:
        """The protocol's episode loop, as `run_trial` runs it: the stopping rule, then the episode count."""
        sim = self.sim
        self.events.add(sim.total_steps, sim.episode, "episode",
                        f"episode {sim.episode} ended, return {sim.last_return:.4g}", sim.last_return)  # fmt: skip
        protocol = self.spec.protocol
        if protocol.episodes == 0:
            return
        stopped, self.stop_reference = stopping_rule(protocol.stop, sim.episode, sim.thetas, self.stop_reference)
        if stopped:
            self._finish(stopped_early=True)
        elif sim.episode >= protocol.episodes:
            self._finish(stopped_early=False)

    def summarize(self, stopped_early: bool) -> Summary:
        """Each demon's prediction at the start point (the grid) or at the agent's state (other worlds)."""
        sim = self.sim
        hs, horde = sim.horde_state, sim.horde
        diverged = dict(zip(horde.names, hs.diverged.tolist(), strict=True))
        predictions = sim.summary_predictions()
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
        self.summary = self.summarize(stopped_early)
        reason = "the stopping rule fired" if stopped_early else "its episodes are done"
        self.set_status("finished", f"finished after {self.sim.episode} episodes: {reason}")
        self._rec.save_quietly(self, snapshot=True)  # no caller to raise to: the message and events say it

    def fail(self, exc: Exception) -> None:
        log.error("a run failed", exc_info=exc)
        self.set_status("failed", f"{type(exc).__name__}: {exc}", kind="error")
        self._rec.save_quietly(self, snapshot=False)
        self._rec.publish(self)

    def set_status(self, status: RunStatus, message: str = "", kind: str = "status") -> None:
        self.status = status
        self.message = message
        sim = self.sim
        self.events.add(sim.total_steps, sim.episode, "error" if kind == "error" else "status", message or status)

    def mark_diverged(self) -> None:
        """Report the demons the engine froze (the core's one divergence rule: `horde.core.learner`)."""
        sim = self.sim
        diverged = sim.readout().diverged  # [D]
        for i in np.nonzero(diverged)[0]:
            name = sim.horde.names[i]
            if name not in self._diverged:
                self._diverged.add(name)
                self.events.add(sim.total_steps, sim.episode, "error", f"demon {name!r} diverged: its numbers went "
                                f"beyond {MAX_MAGNITUDE:g} or non-finite; it is frozen")  # fmt: skip

    # ------------------------------------------------------------------------------------------
    # What each command may do (the learner thread runs them; LiveRun saves and publishes after)

    def require(self, allowed: tuple[RunStatus, ...], action: str) -> None:
        if self.status not in allowed:
            hint = {
                "running": "pause it first",
                "finished": "reset it to run again",
                "failed": f"it failed ({self.message}); reset it",
            }.get(self.status, "")
            raise ConflictError(f"cannot {action} a {self.status} run" + (f": {hint}" if hint else ""))

    def start(self) -> None:
        self.require(("created", "paused"), "start")
        self.set_status("running", "running")

    def pause(self) -> None:
        self.require(("running",), "pause")
        if self._rec.recorded_to() < self.sim.total_steps:  # the history (and its charts) ends where the run stands
            self._rec.record(self, measure=True)
        self._rec.measure_end(self)
        self.set_status("paused", f"paused at step {self.sim.total_steps}")

    def reset(self) -> None:
        self.sim = new_source(self.spec)
        self.summary = None
        self.stop_reference = self.sim.thetas()
        self._rec.new_history(self.sim.horde.names)
        self.set_status("created", "reset")

    def step(self, steps: int) -> None:
        self.require(("created", "paused"), "step")
        if self.status == "created":
            self.set_status("paused", "stepped")
        self.learn(min(steps, self.limits.max_step_request), None)
        self._rec.measure_end(self)  # RMSVE and RMSPBE where the steps ended

    def patch(self, set_hz: bool, hz: float | None, behaviour: BehaviourSpec | None) -> None:
        if behaviour is not None:
            self.spec = self._respec(behaviour=behaviour.model_dump(by_alias=True))
            self.sim.spec = self.spec
        if set_hz:
            if hz is not None and not MIN_HZ <= hz <= MAX_HZ:
                raise SpecError.at(("body", "hz"), f"hz must lie in [{MIN_HZ}, {MAX_HZ:g}] (or be null)")
            self.hz = hz

    def add_demon(self, demon: DemonSpec) -> None:
        self.require(("created", "running", "paused"), "add demons to")
        if demon.name in self.sim.horde.index:
            raise ConflictError(f"the run already has a demon {demon.name!r}")
        demons = [d.model_dump(by_alias=True) for d in self.spec.demons] + [demon.model_dump(by_alias=True)]
        spec = self._respec(demons=demons)
        check_limits(spec, self.limits)
        self._swap_horde(spec, f"demon {demon.name!r} joined")

    def remove_demon(self, name: str, run_id: str) -> None:
        if name not in self.sim.horde.index:
            raise NotFoundError(f"run {run_id!r} has no demon {name!r}")
        self.require(("created", "running", "paused"), "remove demons from")
        readers = sorted(
            d.name for d in self.spec.demons if d.name != name and name in demon_dependencies(d, self.spec.features)
        )
        if readers:
            raise ConflictError(f"cannot remove demon {name!r}: {', '.join(repr(r) for r in readers)} read its "
                                "prediction or policy; remove those first")  # fmt: skip
        if self.spec.behaviour.demon == name:
            raise ConflictError(f"cannot remove demon {name!r}: the behaviour policy acts on it")
        demons = [d.model_dump(by_alias=True) for d in self.spec.demons if d.name != name]
        try:
            spec = self._respec(demons=demons)
        except SpecError as exc:
            raise ConflictError(f"cannot remove demon {name!r}: {exc.problems[0].msg}") from None
        self._swap_horde(spec, f"demon {name!r} left")

    def _respec(self, **changes: Any) -> RunSpec:
        """The current spec with some top-level fields replaced, validated again."""
        data = self.spec.model_dump(by_alias=True)
        data.update(changes)
        try:
            return resolve_world(RunSpec.model_validate(data))  # a Gymnasium world: its sensors checked too
        except ValidationError as exc:
            raise SpecError.from_validation(exc, ("body",)) from None

    def _swap_horde(self, spec: RunSpec, message: str) -> None:
        """A new Horde for a changed set of demons, keeping every remaining demon's weights."""
        sim = self.sim = self.sim.with_spec(spec)
        self.spec = spec
        self._rec.remap(sim.horde.names)
        self.stop_reference = sim.thetas()
        self.events.add(sim.total_steps, sim.episode, "demon", message)
