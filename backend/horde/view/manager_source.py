"""The server's runs as the live view sees them: `RunManager` behind the `ViewSource` protocol.

Everything the view reads comes from a run's published `RunView` (an immutable copy) and its
history buffer, as every reader's; value maps, greedy actions, phase planes and Baird's star are asked of
the run's worker, and commands go to it like REST requests do. The agent's trail is sampled from the views the live view
takes (about 30 a second), which is every step when watching and a sample at full speed.

Runs of a world without a plane are drawn as a phase plane of two sensors (`phase_snapshot`): live runs
of a Gymnasium environment (played, paused and stepped as grid runs are; their trail is sampled from the
views as the grid's is), and stream runs (`StreamRuns`, given as `streams`, listed after the live runs and
labelled "stream"), whose commands are refused: a stream run learns what its clients push. A run on
Baird's star is drawn as the star instead (`star`, `horde.view.star`).
"""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Sequence

import numpy as np

from horde.runs.errors import NotFoundError, RunError, SpecError
from horde.runs.evaluations import forget_evaluations
from horde.runs.manager import RunManager
from horde.runs.run_view import RunView
from horde.runs.stream_run import StreamRun, StreamRuns
from horde.view.source import CommandRefusedError, History, PhaseSnapshot, ViewSnapshot
from horde.worlds.baird import BAIRD_ID, UPPER
from horde.worlds.phase_plane import Axis

TRAIL_POINTS = 500  # most positions kept of one episode's trail
HISTORY_ROWS = 400  # most rows of a demon's history sent to the charts


class ManagerSource:
    """`ViewSource` over a `RunManager`.

    Args:
        manager: the server's runs.
        streams: the server's stream runs, drawn as phase planes (None: grid runs only).
    """

    def __init__(self, manager: RunManager, streams: StreamRuns | None = None) -> None:
        self.manager = manager
        self.streams = streams
        self._lock = threading.Lock()
        self._trails: dict[str, tuple[int, deque[tuple[float, float]]]] = {}  # run -> (episode, points)
        self._sensor_trails: dict[str, tuple[int, deque[np.ndarray]]] = {}  # run -> (seq, sensors [S] each)

    def _view(self, run_id: str) -> RunView:
        try:
            return self.manager.get(run_id).view
        except NotFoundError:
            raise KeyError(run_id) from None

    def list_runs(self) -> list[tuple[str, str]]:
        views = sorted(self.manager.list(), key=lambda v: v.created_at)
        streams = sorted(self.streams.list(), key=lambda r: r.created) if self.streams is not None else []
        return [(v.id, v.spec.name or "") for v in views] + [(r.id, f"stream {r.spec.name or ''}".strip())
                                                             for r in streams]  # fmt: skip

    def is_stream(self, run_id: str) -> bool:
        """Whether the run is a stream run (it learns what clients push: no commands)."""
        if self.streams is None:
            return False
        try:
            self.streams.get(run_id)
        except NotFoundError:
            return False
        return True

    def is_phase(self, run_id: str) -> bool:
        """Whether the run is drawn as a phase plane (a stream run, or a live run of a Gymnasium world)."""
        if self.is_stream(run_id):
            return True
        try:
            return self.manager.get(run_id).view.spec.world.kind != "grid"
        except NotFoundError:
            return False

    def phase_status(self, run_id: str) -> tuple[tuple[str, ...], tuple[str, ...], int, int]:
        """A phase-plane run's (sensor names, demon names, records received or steps, records learned or
        steps): cheap, every frame; a live run's sensors join its trail here."""
        if not self.is_stream(run_id):
            view = self._view(run_id)
            self._sample_sensors(view)
            names = tuple(view.spec.world.sensor_names())
            return names, tuple(view.names), view.total_steps, view.total_steps
        run = self._stream(run_id)
        status = run.status()
        return tuple(run.spec.world.sensor_names()), tuple(run.names), status.received, status.learned

    def _sample_sensors(self, view: RunView) -> np.ndarray:
        """[N, S] the live run's recent sensor readings, the view's own appended once per publication."""
        with self._lock:
            seq, points = self._sensor_trails.get(view.id, (-1, deque(maxlen=TRAIL_POINTS)))
            if view.sensors is not None and seq != view.seq:
                points.append(view.sensors)
            self._sensor_trails[view.id] = (view.seq, points)
            return np.array(points).reshape(len(points), -1)

    def _live_phase(self, view: RunView, demon: str | None, x: str | None, y: str | None,
                    resolution: int) -> PhaseSnapshot:  # fmt: skip
        """A Gymnasium run's phase plane, its values read by the run's worker."""
        sensors = tuple(view.spec.world.sensor_names())
        demon = demon or view.names[0]
        x, y = x or sensors[0], y or sensors[min(1, len(sensors) - 1)]
        if demon not in view.index:
            raise KeyError(demon)
        try:
            phase = self.manager.get(view.id).phase(demon, x, y, resolution)
        except NotFoundError as exc:  # a sensor the world does not have, or a run deleted meanwhile
            raise KeyError(str(exc)) from None
        except RunError:  # its worker is gone (a failed run) or busy: no values to draw
            return self._blank_phase(view, demon, x, y, resolution)
        trail = self._sample_sensors(view)
        columns = [sensors.index(x), sensors.index(y)]
        return PhaseSnapshot(run_id=view.id, sensors=sensors, demons=tuple(view.names),
                             received=view.total_steps, learned=view.total_steps, demon=demon, x=phase.x, y=phase.y,
                             values=phase.values, trail=trail[:, columns] if len(trail) else np.zeros((0, 2)),
                             predictions=dict(zip(view.names, view.prediction.tolist(), strict=True)))  # fmt: skip

    def _blank_phase(self, view: RunView, demon: str, x: str, y: str, resolution: int) -> PhaseSnapshot:
        """A phase plane without values (the run's worker cannot be asked)."""
        bounds = view.spec.world.sensor_bounds()
        axes = []
        for sensor in (x, y):
            low, high = bounds.get(sensor, (0.0, 1.0))
            axes.append(
                Axis(sensor, float(low) if np.isfinite(low) else 0.0, float(high) if np.isfinite(high) else 1.0)
            )
        return PhaseSnapshot(run_id=view.id, sensors=tuple(view.spec.world.sensor_names()), demons=tuple(view.names),
                             received=view.total_steps, learned=view.total_steps, demon=demon, x=axes[0], y=axes[1],
                             values=np.full((resolution, resolution), np.nan), trail=np.zeros((0, 2)),
                             predictions=dict(zip(view.names, view.prediction.tolist(), strict=True)))  # fmt: skip

    def star(self, run_id: str, demon: str | None) -> tuple[str, np.ndarray, int, bool] | None:
        """A live run on Baird's star (`horde/Baird-v0`): (the demon shown, its values at the seven states [7],
        the agent's state, whether the demon diverged); None for any other run. Raises KeyError for an unknown
        run or demon."""
        if self.is_stream(run_id):
            return None
        view = self._view(run_id)
        if getattr(view.spec.world, "id", None) != BAIRD_ID:
            return None
        demon = demon or view.names[0]
        if demon not in view.index:
            raise KeyError(demon)
        try:
            values = self.manager.get(run_id).star(demon)  # [7]
        except NotFoundError:
            raise KeyError(run_id) from None
        except RunError:  # its worker is gone (a failed run) or busy: no values to draw
            values = np.full(UPPER + 1, np.nan)
        state = int(view.sensors[0]) if view.sensors is not None else 0
        return demon, values, state, bool(view.diverged[view.index[demon]])

    def _stream(self, run_id: str) -> StreamRun:
        if self.streams is None:
            raise KeyError(run_id)
        try:
            return self.streams.get(run_id)
        except NotFoundError:
            raise KeyError(run_id) from None

    def phase_snapshot(self, run_id: str, demon: str | None, x: str | None, y: str | None,
                       resolution: int) -> PhaseSnapshot:  # fmt: skip
        """The stream run's phase plane: `demon`'s values over sensors x and y (None: the first demon, the
        first two sensors). Raises KeyError for an unknown run, demon or sensor."""
        if not self.is_stream(run_id):
            return self._live_phase(self._view(run_id), demon, x, y, resolution)
        run = self._stream(run_id)
        sensors = tuple(run.spec.world.sensor_names())
        demon = demon or run.names[0]
        x = x or sensors[0]
        y = y or sensors[min(1, len(sensors) - 1)]
        try:
            ax, ay, values, trail = run.phase_plane(demon, x, y, resolution)
        except SpecError as exc:
            raise KeyError(str(exc)) from None
        status = run.status()
        return PhaseSnapshot(run_id=run.id, sensors=sensors, demons=tuple(run.names), received=status.received,
                             learned=status.learned, demon=demon, x=ax, y=ay, values=values, trail=trail,
                             predictions=dict(zip(run.names, status.predictions.tolist(), strict=True)))  # fmt: skip

    def _trail(self, view: RunView) -> tuple[tuple[float, float], ...]:
        with self._lock:
            episode, points = self._trails.get(view.id, (-1, deque(maxlen=TRAIL_POINTS)))
            if episode != view.episode:
                points = deque(maxlen=TRAIL_POINTS)
            if not points or points[-1] != view.position:
                points.append(view.position)
            self._trails[view.id] = (view.episode, points)
            return tuple(points)

    def snapshot(self, run_id: str, demons: Sequence[str] | None = None) -> ViewSnapshot:
        view = self._view(run_id)
        names = [n for n in (demons if demons is not None else view.names) if n in view.index]
        index = [view.index[n] for n in names]
        colors = {}
        regions = view.spec.grid.regions if view.spec.world.kind == "grid" else []
        for slot, region in enumerate(r for r in regions if r.kind == "indicator"):
            colors[region.name] = (region.colors or [])[view.colors[slot]].name
        return ViewSnapshot(
            run_id=view.id,
            spec=view.spec,
            x=view.position[0],
            y=view.position[1],
            trail=self._trail(view),
            episode=view.episode,
            episode_step=view.episode_step,
            total_steps=view.total_steps,
            episode_return=view.episode_return,
            status=view.status,
            hz=view.hz,
            predictions={n: float(view.prediction[i]) for n, i in zip(names, index, strict=True)},
            rupee={n: float(view.rupee[i]) for n, i in zip(names, index, strict=True)},
            indicator_colors=colors,
            history=self._history(run_id, names),
        )

    def _history(self, run_id: str, names: Sequence[str]) -> History:
        history = self.manager.get(run_id).history
        predictions, rupee = {}, {}
        steps = np.zeros(0)
        for name in names:
            try:
                series = history.series(name, HISTORY_ROWS)
            except KeyError:
                continue
            steps = series.steps
            predictions[name] = series.values["prediction"]
            rupee[name] = series.values["rupee"]
        return History(steps=steps, predictions=predictions, rupee=rupee)

    def value_map(self, run_id: str, demon: str, resolution: int) -> np.ndarray:
        view = self._view(run_id)
        if demon not in view.index:
            raise KeyError(demon)
        try:
            values: np.ndarray = self.manager.get(run_id).value_map(demon, resolution).values
        except NotFoundError:
            raise KeyError(run_id) from None
        except RunError:  # its worker is gone (a failed run) or busy: no values to draw
            return np.full((resolution, resolution), np.nan)
        return values

    def greedy_actions(self, run_id: str, demon: str, resolution: int) -> np.ndarray | None:
        view = self._view(run_id)
        if demon not in view.index:
            raise KeyError(demon)
        if not view.control[view.index[demon]]:
            return None
        try:
            return self.manager.get(run_id).greedy_actions(demon, resolution)
        except NotFoundError:
            raise KeyError(run_id) from None
        except RunError:
            return None

    def _command(self, run_id: str, name: str, *args: object, **kwargs: object) -> None:
        """Call the run's command; what it refuses (say, play when finished) or cannot save is told back."""
        if self.is_stream(run_id):
            raise CommandRefusedError("a stream run learns the records its clients push: it has no play, pause, "
                                      "step, reset or speed")  # fmt: skip
        try:
            run = self.manager.get(run_id)
        except NotFoundError:
            raise KeyError(run_id) from None
        try:
            getattr(run, name)(*args, **kwargs)
        except NotFoundError:
            raise KeyError(run_id) from None  # deleted meanwhile
        except RunError as exc:
            raise CommandRefusedError(str(exc)) from None

    def play(self, run_id: str) -> None:
        self._command(run_id, "start")

    def pause(self, run_id: str) -> None:
        self._command(run_id, "pause")

    def step(self, run_id: str, n: int = 1) -> None:
        self._command(run_id, "step", n)

    def reset(self, run_id: str) -> None:
        self._command(run_id, "reset")
        if self.manager.store is not None:  # fresh weights: the kept evaluations no longer describe them
            forget_evaluations(self.manager.store, run_id)

    def set_hz(self, run_id: str, hz: float | None) -> None:
        self._command(run_id, "patch", set_hz=True, hz=hz)
