"""One agent in one world with its Horde: the loop that the protocol, the CLI and the server drive.

`Simulation` holds immutable states (`WorldState`, `HordeState`) and replaces them at every step; it is
the only mutable object of the core, and it is not thread-safe: the run manager owns one per run.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from horde.core.horde import Horde, HordeState
from horde.core.policies import sample
from horde.core.world import World, WorldState
from horde.spec import BehaviourSpec, RunSpec


@dataclass(frozen=True)
class StepResult:
    """What one step of the agent did."""

    action: int
    reward: float
    terminated: bool
    truncated: bool
    terminal_sign: float  # +1 / -1 where the episode ended in a positive / negative terminal, else 0

    @property
    def done(self) -> bool:
        return self.terminated or self.truncated


class Simulation:
    """The agent, its world and its Horde, with a seeded generator.

    Args:
        spec: the run spec.
        rng: the generator (default: seeded from spec.seed).
    """

    def __init__(self, spec: RunSpec, rng: np.random.Generator | None = None) -> None:
        self.spec = spec
        self.world = World(spec.world)
        self.horde = Horde(spec)
        self.rng = rng if rng is not None else np.random.default_rng(spec.seed)
        self.episode = 0
        self.total_steps = 0
        self.episode_return = 0.0
        self.last_return = 0.0
        self.with_metrics = True
        self.horde_state: HordeState = self.horde.init_state()
        self.world_state: WorldState = self.world.reset(self.rng)
        self.horde_state = self.horde.start_episode(self.horde_state, *self.position)

    @property
    def position(self) -> tuple[float, float]:
        return float(self.world_state.x[0]), float(self.world_state.y[0])

    def new_episode(self) -> None:
        self.episode += 1
        self.last_return = self.episode_return
        self.episode_return = 0.0
        self.world_state = self.world.reset(self.rng)
        self.horde_state = self.horde.start_episode(self.horde_state, *self.position)

    def step(self, behaviour: BehaviourSpec | None = None, learning: np.ndarray | None = None) -> StepResult:
        """Act with the behaviour policy, learn from the transition, and start a new episode when it ends.

        Args:
            behaviour: overrides the run's behaviour (test runs use a greedy one).
            learning: [D] bool, which demons learn (default all).
        """
        hs = self.horde_state
        b = self.horde.behaviour_probs(hs.q[None], behaviour)  # [1, A]
        action = sample(b, self.rng)  # [1]
        ws, transition = self.world.step(self.world_state, action, self.rng)
        sensors = self.world.sensors(ws, transition)[0]  # [S]
        terminated = bool(transition.terminated[0])
        sign = float(self.world.terminal_sign(ws, transition.inside)[0]) if terminated else 0.0
        self.horde_state = self.horde.learn(
            hs,
            int(action[0]),
            float(b[0, action[0]]),
            float(ws.x[0]),
            float(ws.y[0]),
            sensors,
            terminated,
            with_metrics=self.with_metrics,
            learning=learning,
        )
        self.world_state = ws
        self.total_steps += 1
        reward = float(transition.reward[0])
        self.episode_return += reward
        result = StepResult(int(action[0]), reward, terminated, bool(transition.truncated[0]), sign)
        if result.done:
            self.new_episode()
        return result

    def run_episode(self, behaviour: BehaviourSpec | None = None, learning: np.ndarray | None = None) -> StepResult:
        """Step until the current episode ends; return its last step."""
        episode = self.episode
        while True:
            result = self.step(behaviour, learning)
            if self.episode != episode:
                return result

    def predictions(self) -> dict[str, float]:
        return dict(zip(self.horde.names, self.horde_state.prediction.tolist(), strict=True))

    def predictions_at(self, x: float, y: float) -> dict[str, float]:
        """Each demon's prediction at a position, with the current weights (nothing learns)."""
        forward = self.horde.forward(self.horde_state, np.array([x]), np.array([y]))
        return dict(zip(self.horde.names, forward.prediction[0].tolist(), strict=True))
