"""What readers see of a run: an immutable view that the learner thread publishes after every chunk.

Readers (REST requests, WebSocket streams) take `LiveRun.view`, an atomic reference, and never touch
the learner's mutable objects: the Horde and its states inside a view are never changed afterwards.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from typing import Literal

import numpy as np

from horde.core.horde import Horde, HordeState
from horde.core.world import WorldState
from horde.spec import RunSpec
from horde.worlds.gym_simulation import GymWorldState

RunStatus = Literal["created", "running", "paused", "finished", "failed"]
STATUSES: tuple[RunStatus, ...] = ("created", "running", "paused", "finished", "failed")


@dataclass(frozen=True)
class Summary:
    """How a finished run ended: each demon's prediction at the start point and its error measures."""

    predictions: dict[str, float]
    rupee: dict[str, float]
    ude: dict[str, float]
    episodes: int
    steps: int
    last_return: float
    stopped_early: bool  # the protocol's stopping rule ended it before its episodes were done

    def to_json(self) -> str:
        return json.dumps(asdict(self))

    @classmethod
    def from_json(cls, text: str) -> Summary:
        return cls(**json.loads(text))


@dataclass(frozen=True)
class RunView:
    """A consistent picture of a run at one moment."""

    id: str
    status: RunStatus
    message: str
    hz: float | None
    spec: RunSpec
    horde: Horde
    horde_state: HordeState  # a copy, never changed
    rupee: np.ndarray  # [D]
    ude: np.ndarray  # [D]
    world_state: WorldState | GymWorldState
    episode: int  # episodes completed
    total_steps: int
    episode_return: float
    last_return: float
    created_at: float  # unix time
    updated_at: float
    summary: Summary | None
    seq: int  # increases with every publication
    step_size: np.ndarray | None = None  # [D] each demon's effective step size (Simulation.effective_step_sizes)
    sensors: np.ndarray | None = None  # [S] the sensors at the agent's state, for a world without a plane

    @property
    def position(self) -> tuple[float, float]:
        """The agent's (x, y) in the grid world; elsewhere its first two sensors (the phase plane's default)."""
        if isinstance(self.world_state, WorldState):
            return float(self.world_state.x[0]), float(self.world_state.y[0])
        sensors = self.sensors if self.sensors is not None else np.zeros(2)
        return float(sensors[0]), float(sensors[min(1, len(sensors) - 1)])

    @property
    def episode_step(self) -> int:
        return int(self.world_state.steps[0])
