"""Reading a run's weights in its worker: value maps' kin (greedy actions, phase planes, Baird's star) and
Monte-Carlo evaluations. The worker's loop copies the weights (a copy shared while it is fresh: `worker.py`) and
goes on learning; the readouts are worked out on the copy in the reader's thread, an evaluation (which may take
seconds) in a thread of its own, and their replies are sent from there. A value map of nexting's 1,710 demons
takes a third of a second on a crowded machine: in the loop it starved the run's learning while the live view
asked for maps.
"""

from __future__ import annotations

import queue
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from horde.core.evaluate import StoppedError
from horde.core.horde import Horde, HordeState
from horde.core.world import WorldState
from horde.runs import messages as m
from horde.runs.errors import NotFoundError, SpecError
from horde.runs.readout import cell_centres, evaluate
from horde.spec import RunSpec
from horde.worlds.gym_simulation import GymWorldState
from horde.worlds.phase_plane import Axis, axis_of, phase_plane

STAR_STATES = 7  # Baird's star: six upper states and the lower one


@dataclass(frozen=True)
class Readable:
    """What the readouts (`readout.value_map`, `readout.evaluate`) read of a run: its weights, frozen or live."""

    id: str
    spec: RunSpec
    horde: Horde
    horde_state: HordeState
    world_state: WorldState | GymWorldState
    total_steps: int


@dataclass(frozen=True)
class PhaseValues:
    """A demon's value map over two sensors, and the axes it spans."""

    x: Axis
    y: Axis
    values: np.ndarray  # [R, R]


def _demon(run: Readable, name: str) -> int:
    if name not in run.horde.index:
        raise NotFoundError(f"run {run.id!r} has no demon {name!r}")
    return run.horde.index[name]


def greedy_actions(run: Readable, demon: str, resolution: int) -> np.ndarray | None:
    """[R, R] a control demon's greedy action per cell of the grid world (`readout.cell_centres`); None for a
    prediction demon."""
    i = _demon(run, demon)
    if not run.horde.is_control(demon):
        return None
    if run.spec.world.kind != "grid":
        raise SpecError.at(("path", "run_id"), "greedy actions over the world need the grid world")
    world = run.spec.grid
    gx, gy = np.meshgrid(*cell_centres(world.width, world.height, resolution))  # [R, R] each, rows along y
    q = run.horde.forward(run.horde_state, gx.ravel(), gy.ravel(), demons=[demon]).q[:, i]  # [R*R, A]
    return np.argmax(q, axis=1).reshape(resolution, resolution)


def phase_values(run: Readable, held: np.ndarray, demon: str, x: str, y: str, resolution: int) -> PhaseValues:
    """A demon's values over sensors x and y, the others held at `held` [S] (the agent's readings)."""
    _demon(run, demon)
    try:
        ax, ay = axis_of(run.horde, x), axis_of(run.horde, y)
    except ValueError as exc:
        raise NotFoundError(str(exc)) from None
    held = np.asarray(held, dtype=float)  # [S]
    return PhaseValues(ax, ay, phase_plane(run.horde, run.horde_state, demon, ax, ay, held, resolution))


def star_values(run: Readable, demon: str) -> np.ndarray:
    """[7] a demon's values at the seven states of Baird's star."""
    i = _demon(run, demon)
    sensors = np.zeros((STAR_STATES, len(run.spec.world.sensor_names())))  # [7, S]
    sensors[:, 0] = np.arange(STAR_STATES)  # the `state` sensor
    zeros = np.zeros(STAR_STATES)
    return run.horde.forward(run.horde_state, zeros, zeros, sensors, [demon]).prediction[:, i]  # [7]


class Reader:
    """The worker's reader: one thread that works readouts out (value maps, greedy actions, phase planes, the star)
    on copies of the weights, in the order they were asked, while the worker's loop learns; `reply` is called
    from that thread with each answer."""

    def __init__(self, reply: Callable[[m.Reply], None]) -> None:
        self.reply = reply
        self._queue: queue.SimpleQueue[tuple[int, Callable[[], Any]]] = queue.SimpleQueue()
        self._thread = threading.Thread(target=self._run, name="horde-reader", daemon=True)
        self._thread.start()

    def submit(self, cid: int, readout: Callable[[], Any]) -> None:
        self._queue.put((cid, readout))

    def _run(self) -> None:
        while True:
            cid, readout = self._queue.get()
            try:
                answer = m.Reply(cid, readout())
            except Exception as exc:
                answer = m.Reply(cid, failure=m.failure_of(exc))
            self.reply(answer)


def evaluate_in_thread(run: Readable, cid: int, command: m.Evaluate, cancel: threading.Event,
                       reply: Callable[[m.Reply], None]) -> None:  # fmt: skip
    """Roll out (`readout.evaluate`) in a thread of its own, stopping at `cancel` or after `command.seconds`;
    `reply` is called from that thread with the answer to call `cid`."""
    deadline: list[float] = []

    def stop() -> bool:  # the budget counts from the first chunk of rollouts (which may compile them)
        if cancel.is_set():
            return True
        if not deadline:
            deadline.append(time.monotonic() + command.seconds)
        return time.monotonic() > deadline[0]

    def roll_out() -> None:
        try:
            value = evaluate(run, command.demon, command.start, command.episodes, command.cap, command.seed, stop)
            answer = m.Reply(cid, value)
        except StoppedError as exc:
            if cancel.is_set():
                answer = m.Reply(cid, failure=m.failure_of(exc))
            else:
                late = SpecError.at(("body", "episodes"), f"the rollouts did not finish within {command.seconds:g} s "
                                    f"({exc}): ask for fewer episodes or a smaller cap")  # fmt: skip
                answer = m.Reply(cid, failure=m.failure_of(late))
        except Exception as exc:
            answer = m.Reply(cid, failure=m.failure_of(exc))
        reply(answer)

    threading.Thread(target=roll_out, name=f"horde-evaluation-{cid}", daemon=True).start()
