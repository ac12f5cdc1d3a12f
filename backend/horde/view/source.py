"""What the live view reads and commands: the `ViewSource` protocol and its `ViewSnapshot`.

The view knows nothing of threads, stores or the server: it asks a source for the runs it may show,
samples frozen snapshots of one run (about 30 a second at most), asks for value maps (a few a second)
and forwards the GUI's commands. The run manager implements this protocol (`ManagerSource`), for the
server, the standalone demo and the tests: the view has one stepping loop behind it, the runs' own.

Grid convention of `value_map` and `greedy_actions` (shared by the scene builder): the world is cut
into `resolution x resolution` cells, and entry `[j, i]` is the value at the centre of cell (i, j),
`horde.runs.readout.cell_centres` (row j grows with y).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np

from horde.spec import RunSpec
from horde.worlds.phase_plane import Axis


class CommandRefusedError(Exception):
    """A command the run refuses (say, play on a finished run) or could not carry out (its save failed);
    the message is meant for the person who clicked."""


@dataclass(frozen=True)
class History:
    """A short window of recent steps of some demons (the GUI's charts).

    Attributes:
        steps: [T] total step count of each sample (the charts' x axis).
        predictions: demon name -> [T] prediction at each sample.
        rupee: demon name -> [T] RUPEE at each sample.
    """

    steps: np.ndarray = field(default_factory=lambda: np.zeros(0))
    predictions: Mapping[str, np.ndarray] = field(default_factory=dict)
    rupee: Mapping[str, np.ndarray] = field(default_factory=dict)


@dataclass(frozen=True)
class ViewSnapshot:
    """One run's state at one moment, copied out of the learner: the view never shares its arrays.

    Attributes:
        run_id: the run.
        spec: its RunSpec (the world to draw, the demons to choose from).
        x, y: the agent's position in world units.
        trail: the agent's positions in this episode so far, oldest first, the current one last.
        episode: episodes started before the current one (0 in the first).
        episode_step: transitions so far in the current episode.
        total_steps: transitions since the run began.
        episode_return: the base problem's return so far in this episode.
        status: created, running, paused, finished or failed.
        hz: steps per second while running, or None for as fast as possible.
        predictions: demon name -> prediction at the agent's position.
        rupee: demon name -> RUPEE (White, 2015).
        indicator_colors: indicator region name -> the colour name drawn for this episode.
        history: recent predictions and RUPEE of the demons the view asked for.
    """

    run_id: str
    spec: RunSpec
    x: float
    y: float
    trail: tuple[tuple[float, float], ...]
    episode: int
    episode_step: int
    total_steps: int
    episode_return: float
    status: str
    hz: float | None
    predictions: Mapping[str, float]
    rupee: Mapping[str, float]
    indicator_colors: Mapping[str, str]
    history: History = field(default_factory=History)


@dataclass(frozen=True)
class PhaseSnapshot:
    """A run of a world without a plane (a stream run) as the view draws it: a phase plane of two sensors.

    Attributes:
        run_id: the run.
        sensors: the world's sensor names (the axes to choose from).
        demons: the run's demon names (the value maps to choose from).
        received, learned: records received (good or refused) and taken in.
        demon: the demon whose value map `values` is, over `x` and `y`.
        x, y: the sensors along the plane's axes, with their ranges.
        values: [R, R] the demon's prediction over the plane (row j at y's j-th cell; nan: diverged).
        trail: [N, 2] the recent (x, y) readings, oldest first, the current one last.
        predictions: demon name -> prediction at the last observation.
    """

    run_id: str
    sensors: tuple[str, ...]
    demons: tuple[str, ...]
    received: int
    learned: int
    demon: str
    x: Axis
    y: Axis
    values: np.ndarray
    trail: np.ndarray
    predictions: Mapping[str, float]


@runtime_checkable
class ViewSource(Protocol):
    """Runs as the live view sees them. Every method is called from the view's own thread.

    Implementations must return quickly (copy under a lock, compute outside it) so that the view
    never slows a learner, and raise KeyError for an unknown run or demon. The commands (play, pause,
    step, reset, set_hz) raise `CommandRefusedError` when the run does not do what was asked; the GUI tells
    the client who clicked.
    """

    def list_runs(self) -> list[tuple[str, str]]:
        """(run_id, label) of every run the view may show, in display order."""
        ...

    def snapshot(self, run_id: str, demons: Sequence[str] | None = None) -> ViewSnapshot:
        """The run's current state; `predictions`, `rupee` and `history` hold only `demons` if given
        (names the run does not have, say a demon that just left it, are left out)."""
        ...

    def value_map(self, run_id: str, demon: str, resolution: int) -> np.ndarray:
        """[resolution, resolution] predictions of `demon` over the world with its current weights."""
        ...

    def greedy_actions(self, run_id: str, demon: str, resolution: int) -> np.ndarray | None:
        """[resolution, resolution] int greedy action (0 up, 1 down, 2 left, 3 right) of a control
        demon over the world, or None if `demon` is not a control demon."""
        ...

    def play(self, run_id: str) -> None:
        """Start or resume stepping at the run's speed."""
        ...

    def pause(self, run_id: str) -> None:
        """Stop stepping; the state is kept."""
        ...

    def step(self, run_id: str, n: int = 1) -> None:
        """Take n steps now (while paused), then stay paused."""
        ...

    def reset(self, run_id: str) -> None:
        """Back to the run's start: fresh weights, episode 0, not stepping (status created)."""
        ...

    def set_hz(self, run_id: str, hz: float | None) -> None:
        """Steps per second while running; None runs as fast as possible."""
        ...
