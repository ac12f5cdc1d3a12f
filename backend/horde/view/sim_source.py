"""`SimulationSource`: a `ViewSource` over Simulation objects in this process, for tests and the demo.

Each run has its own stepping thread and lock. A step holds the lock; snapshots and value maps only
hold it to pick up references (the core replaces its state objects at every step and never changes
them), so the view never waits for more than one step and a learner never waits for the view.
`step(n)` is synchronous here: it pauses the run and takes the n steps in the caller's thread.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterable, Sequence

import numpy as np

from horde.core.horde import HordeState
from horde.core.simulation import Simulation
from horde.spec import RunSpec
from horde.view.history import Ring
from horde.view.source import History, ViewSnapshot

FULL_SPEED_CHUNK = 50  # steps per lock hold when running as fast as possible
HISTORY_LENGTH = 500  # samples kept for the charts


def cell_centres(width: float, height: float, resolution: int) -> tuple[np.ndarray, np.ndarray]:
    """x, y [resolution * resolution] of the cell centres, row by row from the bottom (source.py)."""
    xs = (np.arange(resolution) + 0.5) * width / resolution  # [res]
    ys = (np.arange(resolution) + 0.5) * height / resolution  # [res]
    gx, gy = np.meshgrid(xs, ys)  # [res, res], row j holds y_j
    return gx.ravel(), gy.ravel()


class _Run:
    """One simulation, its lock, its speed, its trail and its recent history."""

    def __init__(self, run_id: str, label: str, spec: RunSpec, hz: float | None) -> None:
        self.run_id = run_id
        self.label = label
        self.spec = spec
        self.hz = hz
        self.lock = threading.Lock()
        self.wake = threading.Event()
        self.status = "created"
        self.error = ""
        self.restart()

    def restart(self) -> None:
        """A fresh simulation (caller holds the lock, or nobody else can see this run yet)."""
        self.sim = Simulation(self.spec)
        self.trail: list[tuple[float, float]] = [self.sim.position]
        self.ring = Ring(HISTORY_LENGTH, self.sim.horde.num_demons)

    def step_locked(self) -> None:
        """One step of the simulation, with the trail and the history (caller holds the lock)."""
        sim = self.sim
        episode = sim.episode
        sim.step()
        if sim.episode != episode:
            self.trail = [sim.position]
        else:
            self.trail.append(sim.position)
        state = sim.horde_state
        self.ring.append(sim.total_steps, state.prediction, sim.horde.rupee(state))


class SimulationSource:
    """Runs simulated in this process, each stepped by its own thread at its own speed.

    Args:
        specs: one run per spec, created paused (status "created").
        hz: steps per second while running (None: as fast as possible).
    """

    def __init__(self, specs: Iterable[RunSpec] = (), hz: float | None = 10.0) -> None:
        self._runs: dict[str, _Run] = {}
        self._threads: list[threading.Thread] = []
        self._closed = threading.Event()
        self._hz = hz
        for spec in specs:
            self.add(spec)

    def add(self, spec: RunSpec, label: str | None = None) -> str:
        """Add a run (paused) and start its thread; returns its id."""
        label = label or spec.name or "run"
        run_id = f"{label}-{len(self._runs) + 1}"
        run = _Run(run_id, label, spec, self._hz)
        self._runs[run_id] = run
        thread = threading.Thread(target=self._loop, args=(run,), name=f"horde-sim-{run_id}", daemon=True)
        self._threads.append(thread)
        thread.start()
        return run_id

    def close(self) -> None:
        """Stop every stepping thread."""
        self._closed.set()
        for run in self._runs.values():
            run.wake.set()
        for thread in self._threads:
            thread.join(timeout=5.0)

    # ------------------------------------------------------------------------------------------
    # The stepping threads

    def _loop(self, run: _Run) -> None:
        next_time = time.monotonic()
        while not self._closed.is_set():
            if run.status != "running":
                run.wake.wait(0.5)
                run.wake.clear()
                next_time = time.monotonic()
                continue
            try:
                if run.hz is None:
                    with run.lock:
                        for _ in range(FULL_SPEED_CHUNK):
                            if run.status == "running":
                                run.step_locked()
                    time.sleep(0)  # let the view and the commands in
                    continue
                delay = next_time - time.monotonic()
                if delay > 0:
                    if run.wake.wait(delay):
                        run.wake.clear()  # a command: look at the status and speed again
                    continue
                with run.lock:
                    if run.status == "running":
                        run.step_locked()
                next_time = max(next_time + 1.0 / run.hz, time.monotonic() - 1.0)
            except Exception as exc:  # a failed run stops; the others go on
                run.status, run.error = "failed", repr(exc)

    # ------------------------------------------------------------------------------------------
    # ViewSource

    def _run(self, run_id: str) -> _Run:
        return self._runs[run_id]

    def list_runs(self) -> list[tuple[str, str]]:
        return [(run.run_id, run.label) for run in self._runs.values()]

    def snapshot(self, run_id: str, demons: Sequence[str] | None = None) -> ViewSnapshot:
        run = self._run(run_id)
        with run.lock:  # references and small copies only; the core never changes its state objects
            sim = run.sim
            state: HordeState = sim.horde_state
            world_state = sim.world_state
            index = sim.horde.index
            names = list(sim.horde.names) if demons is None else [name for name in demons if name in index]
            columns = [index[name] for name in names]
            steps, predictions, rupee = run.ring.columns(columns)  # [T], [T, d], [T, d]
            episode, total_steps, episode_return = sim.episode, sim.total_steps, sim.episode_return
            trail = tuple(run.trail)
            status, hz = run.status, run.hz
        world = sim.world
        colors = {
            world.region_names[region]: world.color_names[slot][int(world_state.colors[0, slot])]
            for slot, region in enumerate(world.indicator_regions)
        }
        return ViewSnapshot(
            run_id=run_id,
            spec=run.spec,
            x=float(world_state.x[0]),
            y=float(world_state.y[0]),
            trail=trail,
            episode=episode,
            episode_step=int(world_state.steps[0]),
            total_steps=total_steps,
            episode_return=episode_return,
            status=status,
            hz=hz,
            predictions=dict(zip(names, state.prediction[columns].tolist(), strict=True)),
            rupee=dict(zip(names, sim.horde.rupee(state)[columns].tolist(), strict=True)),
            indicator_colors=colors,
            history=History(
                steps=steps,
                predictions={name: predictions[:, k] for k, name in enumerate(names)},
                rupee={name: rupee[:, k] for k, name in enumerate(names)},
            ),
        )

    def _forward(self, run_id: str, demon: str, resolution: int) -> tuple[np.ndarray, np.ndarray, int]:
        run = self._run(run_id)
        with run.lock:
            horde, state = run.sim.horde, run.sim.horde_state
        index = horde.index[demon]
        xs, ys = cell_centres(run.spec.grid.width, run.spec.grid.height, resolution)
        forward = horde.forward(state, xs, ys)
        return forward.prediction, forward.q, index

    def value_map(self, run_id: str, demon: str, resolution: int) -> np.ndarray:
        prediction, _, index = self._forward(run_id, demon, resolution)
        return prediction[:, index].reshape(resolution, resolution)  # [res, res]

    def greedy_actions(self, run_id: str, demon: str, resolution: int) -> np.ndarray | None:
        run = self._run(run_id)
        if not run.sim.horde.is_control(demon):
            return None
        _, q, index = self._forward(run_id, demon, resolution)
        return np.argmax(q[:, index, :], axis=-1).reshape(resolution, resolution)  # [res, res]

    def _command(self, run: _Run, status: str) -> None:
        if run.status != "failed":
            run.status = status
        run.wake.set()

    def play(self, run_id: str) -> None:
        self._command(self._run(run_id), "running")

    def pause(self, run_id: str) -> None:
        self._command(self._run(run_id), "paused")

    def step(self, run_id: str, n: int = 1) -> None:
        run = self._run(run_id)
        self._command(run, "paused")
        with run.lock:
            for _ in range(max(0, int(n))):
                run.step_locked()

    def reset(self, run_id: str) -> None:
        run = self._run(run_id)
        with run.lock:
            run.restart()
            run.status, run.error = "created", ""
        run.wake.set()

    def set_hz(self, run_id: str, hz: float | None) -> None:
        run = self._run(run_id)
        run.hz = None if hz is None else max(float(hz), 1e-3)
        run.wake.set()
