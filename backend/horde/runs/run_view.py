"""What readers see of a run: an immutable view made of the latest view its worker published (`PublishedView`,
part of the message protocol of `messages.py`).

Readers (REST requests, WebSocket streams, the live view) take `LiveRun.view`, an atomic reference, in the
API process: the numbers a run's worker published (`messages.PublishedView`), its spec, and what the API
process itself knows of it (a save that failed, a worker that stopped answering or died). A view holds no
weights: value maps, evaluations and snapshots are asked of the worker.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from functools import cached_property
from typing import Literal

import numpy as np

from horde.core.policies import KIND_CODES, OWN_VALUE
from horde.spec import DemonSpec, RunSpec

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


def is_control(demon: DemonSpec) -> bool:
    """Whether a demon is a control demon: GQ with a target policy over its own action values."""
    return demon.learner == "gq" and KIND_CODES[demon.policy.kind] in OWN_VALUE


@dataclass(frozen=True)
class Worker:
    """Where a run learns: a process of this machine (`pid`) or a Ray actor (`node`), and whether it is alive."""

    kind: Literal["process", "ray", "none"]
    pid: int | None = None
    node: str | None = None
    alive: bool = False


NO_WORKER = Worker("none")


@dataclass(frozen=True)
class PublishedView:
    """A live run at one moment, as every reader sees it (the API's `RunView` is made of it). Arrays are [D] in
    the order of the spec's demons; none is ever changed after it is sent."""

    status: RunStatus
    message: str
    hz: float | None
    episode: int
    total_steps: int
    episode_step: int
    episode_return: float
    last_return: float
    position: tuple[float, float]
    sensors: np.ndarray | None  # [S] at the agent's state, for a world without a plane
    colors: tuple[int, ...]  # each indicator's colour this episode (the grid)
    summary: Summary | None
    seq: int
    updated_at: float
    prediction: np.ndarray  # [D]
    cumulant: np.ndarray  # [D]
    delta: np.ndarray  # [D]
    rupee: np.ndarray  # [D]
    ude: np.ndarray  # [D]
    diverged: np.ndarray  # [D] bool
    step_size: np.ndarray | None  # [D]


@dataclass(frozen=True)
class RunView:
    """A consistent picture of a run at one moment. Arrays are [D] in the order of `spec.demons`."""

    id: str
    status: RunStatus
    message: str
    hz: float | None
    spec: RunSpec
    episode: int  # episodes completed
    total_steps: int
    episode_step: int
    episode_return: float
    last_return: float
    position: tuple[float, float]  # the agent's (x, y) on the grid; elsewhere its first two sensors
    created_at: float  # unix time
    updated_at: float
    summary: Summary | None
    seq: int  # increases with every publication
    prediction: np.ndarray  # [D]
    cumulant: np.ndarray  # [D]
    delta: np.ndarray  # [D]
    rupee: np.ndarray  # [D]
    ude: np.ndarray  # [D]
    diverged: np.ndarray  # [D] bool
    step_size: np.ndarray | None = None  # [D] each demon's effective step size
    sensors: np.ndarray | None = None  # [S] the sensors at the agent's state, for a world without a plane
    colors: tuple[int, ...] = ()  # each indicator's colour (its index in the region's `colors`) this episode
    worker: Worker = NO_WORKER

    @cached_property
    def names(self) -> list[str]:
        return [d.name for d in self.spec.demons]

    @cached_property
    def index(self) -> dict[str, int]:
        return {name: i for i, name in enumerate(self.names)}

    @cached_property
    def control(self) -> np.ndarray:
        """[D] whether each demon is a control demon."""
        return np.array([is_control(d) for d in self.spec.demons], dtype=bool)

    @property
    def num_demons(self) -> int:
        return len(self.spec.demons)


def published_view(run_id: str, spec: RunSpec, published: PublishedView, status: RunStatus, message: str,
                   created_at: float, seq: int, worker: Worker) -> RunView:  # fmt: skip
    """The view of what a run's worker published, with the status and message the API process says."""
    p = published
    return RunView(id=run_id, status=status, message=message, hz=p.hz, spec=spec, episode=p.episode,
                   total_steps=p.total_steps, episode_step=p.episode_step, episode_return=p.episode_return,
                   last_return=p.last_return, position=p.position, created_at=created_at, updated_at=p.updated_at,
                   summary=p.summary, seq=seq, prediction=p.prediction, cumulant=p.cumulant, delta=p.delta,
                   rupee=p.rupee, ude=p.ude, diverged=p.diverged, step_size=p.step_size, sensors=p.sensors,
                   colors=p.colors, worker=worker)  # fmt: skip


def stored_view(run_id: str, spec: RunSpec, status: RunStatus, message: str, summary: Summary | None,
                created_at: float, hz: float | None = None, episode: int = 0, steps: int = 0) -> RunView:  # fmt: skip
    """The view of a run that has published nothing (yet, or since a restart left it without a worker)."""
    nan = np.full(len(spec.demons), np.nan)  # [D]
    return RunView(id=run_id, status=status, message=message, hz=hz, spec=spec, episode=episode, total_steps=steps,
                   episode_step=0, episode_return=0.0, last_return=0.0, position=(0.0, 0.0), created_at=created_at,
                   updated_at=created_at, summary=summary, seq=0, prediction=nan, cumulant=nan, delta=nan, rupee=nan,
                   ude=nan, diverged=np.zeros(len(nan), dtype=bool))  # fmt: skip
