"""One agent in one world with its Horde: the loop that the protocol, the CLI and the server drive.

Two engines run the same loop and draw the same numbers from the same generator in the same order:
`"fast"` (compiled kernels, `fast.py`, the default) and `"numpy"` (the readable vectorized engine,
`world.py` + `horde.py`). Tests hold them equal. `Simulation` is the only mutable object of the core and
is not thread-safe: the run manager owns one per run.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from horde.core.fast import (
    R_ACTION,
    R_EPISODES,
    R_REWARD,
    R_SIGN,
    R_STEPS,
    R_TERMINATED,
    R_TRUNCATED,
    FastLoop,
)
from horde.core.horde import Horde, HordeState
from horde.core.policies import sample
from horde.core.world import World, WorldState
from horde.spec import BehaviourSpec, RunSpec

Engine = Literal["fast", "numpy"]


@dataclass(frozen=True)
class StepResult:
    """What the last step of the agent did."""

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
        engine: "fast" (compiled) or "numpy".
    """

    def __init__(self, spec: RunSpec, rng: np.random.Generator | None = None, engine: Engine = "fast") -> None:
        self.spec = spec
        self.engine = engine
        self.world = World(spec.world)
        self.horde = Horde(spec)
        self.rng = rng if rng is not None else np.random.default_rng(spec.seed)
        self.episode = 0
        self.total_steps = 0
        self.with_metrics = True
        self._numpy_return = [0.0, 0.0]
        self._loop = FastLoop(self.horde, self.world) if engine == "fast" else None
        self._horde_state: HordeState = self.horde.init_state()
        self._world_state: WorldState = (
            self.world.reset(self.rng, 1)
            if self._loop is None
            else WorldState(np.zeros(1), np.zeros(1), np.zeros(1, dtype=np.int64), np.zeros((1, 0), dtype=np.int64))
        )
        if self._loop is not None:
            self._loop.reset_world(self.rng)
        else:
            self._horde_state = self.horde.start_episode(self._horde_state, *self.position)

    # ------------------------------------------------------------------------------------------
    # State

    @property
    def horde_state(self) -> HordeState:
        """The Horde's state (an immutable snapshot: the fast engine hands out a copy)."""
        return self._loop.horde_state() if self._loop is not None else self._horde_state

    @horde_state.setter
    def horde_state(self, state: HordeState) -> None:
        if self._loop is not None:
            self._loop.load(state, self.world_state)
        else:
            self._horde_state = state

    @property
    def world_state(self) -> WorldState:
        return self._loop.world_state() if self._loop is not None else self._world_state

    @world_state.setter
    def world_state(self, state: WorldState) -> None:
        if self._loop is not None:
            self._loop.load(self._loop.horde_state(), state)
        else:
            self._world_state = state

    @property
    def position(self) -> tuple[float, float]:
        if self._loop is not None:
            return float(self._loop.pos[0]), float(self._loop.pos[1])
        return float(self._world_state.x[0]), float(self._world_state.y[0])

    @property
    def episode_return(self) -> float:
        """The return of the episode under way."""
        return float(self._loop.returns[0]) if self._loop is not None else self._numpy_return[0]

    @property
    def last_return(self) -> float:
        """The return of the last finished episode."""
        return float(self._loop.returns[1]) if self._loop is not None else self._numpy_return[1]

    def set_returns(self, episode_return: float, last_return: float) -> None:
        """Restore the return of the episode under way and of the last finished one (snapshots)."""
        if self._loop is not None:
            self._loop.returns[:] = (episode_return, last_return)
        else:
            self._numpy_return = [episode_return, last_return]

    def with_spec(self, spec: RunSpec) -> Simulation:
        """The same agent under a changed set of demons: same world state, generator and counters.

        Every demon that this simulation also has keeps its weights (`Horde.carry_over`); traces restart
        as at an episode start. The generator's state is left exactly as it was.
        """
        rng_state = self.rng.bit_generator.state
        new = Simulation(spec, self.rng, self.engine)  # draws a start: the generator is put back below
        self.rng.bit_generator.state = rng_state
        new.world_state = self.world_state
        new.horde_state = new.horde.carry_over(self.horde, self.horde_state, *self.position)
        new.episode = self.episode
        new.total_steps = self.total_steps
        new.with_metrics = self.with_metrics
        new.set_returns(self.episode_return, self.last_return)
        return new

    # ------------------------------------------------------------------------------------------
    # Acting

    def new_episode(self) -> None:
        """Abandon the episode under way and start a new one."""
        self.episode += 1
        if self._loop is not None:
            self._loop.returns[:] = (0.0, self._loop.returns[0])
            self._loop.reset_world(self.rng)
            return
        self._numpy_return = [0.0, self._numpy_return[0]]
        self._world_state = self.world.reset(self.rng)
        self._horde_state = self.horde.start_episode(self._horde_state, *self.position)

    def step(self, behaviour: BehaviourSpec | None = None, learning: np.ndarray | None = None) -> StepResult:
        """Act with the behaviour policy, learn from the transition, and start a new episode when it ends.

        Args:
            behaviour: overrides the run's behaviour (test runs use a greedy one).
            learning: [D] bool, which demons learn (default all).
        """
        if self._loop is not None:
            return self.run(1, behaviour=behaviour, learning=learning)
        hs = self._horde_state
        b = self.horde.behaviour_probs(hs.q[None], behaviour)  # [1, A]
        action = sample(b, self.rng)  # [1]
        ws, transition = self.world.step(self._world_state, action, self.rng)
        sensors = self.world.sensors(ws, transition)[0]  # [S]
        terminated = bool(transition.terminated[0])
        sign = float(self.world.terminal_sign(ws, transition.inside)[0]) if terminated else 0.0
        self._horde_state = self.horde.learn(
            hs, int(action[0]), float(b[0, action[0]]), float(ws.x[0]), float(ws.y[0]), sensors, terminated,
            with_metrics=self.with_metrics, learning=learning,
        )  # fmt: skip
        self._world_state = ws
        self.total_steps += 1
        reward = float(transition.reward[0])
        self._numpy_return[0] += reward
        result = StepResult(int(action[0]), reward, terminated, bool(transition.truncated[0]), sign)
        if result.done:
            self.episode += 1
            self._numpy_return = [0.0, self._numpy_return[0]]
            self._world_state = self.world.reset(self.rng)
            self._horde_state = self.horde.start_episode(self._horde_state, *self.position)
        return result

    def run(
        self,
        max_steps: int,
        max_episodes: int = 2**62,
        behaviour: BehaviourSpec | None = None,
        learning: np.ndarray | None = None,
    ) -> StepResult:
        """Step until `max_steps` steps or until `max_episodes` episodes have ended; return the last step."""
        if self._loop is None:
            ended = 0
            result = StepResult(0, 0.0, False, False, 0.0)
            for _ in range(max_steps):
                result = self.step(behaviour, learning)
                ended += result.done
                if ended >= max_episodes:
                    break
            return result
        out = self._loop.run(self.rng, max_steps, max_episodes, behaviour, learning, self.with_metrics)
        self.total_steps += int(out[R_STEPS])
        self.episode += int(out[R_EPISODES])
        return StepResult(
            int(out[R_ACTION]),
            float(out[R_REWARD]),
            bool(out[R_TERMINATED]),
            bool(out[R_TRUNCATED]),
            float(out[R_SIGN]),
        )

    def run_episode(self, behaviour: BehaviourSpec | None = None, learning: np.ndarray | None = None) -> StepResult:
        """Step until the current episode ends; return its last step."""
        return self.run(2**62, 1, behaviour, learning)

    # ------------------------------------------------------------------------------------------
    # Reading out

    def predictions(self) -> dict[str, float]:
        prediction = self._loop.pred if self._loop is not None else self._horde_state.prediction
        return dict(zip(self.horde.names, prediction.tolist(), strict=True))

    def predictions_at(self, x: float, y: float) -> dict[str, float]:
        """Each demon's prediction at a position, with the current weights (nothing learns)."""
        forward = self.horde.forward(self.horde_state, np.array([x]), np.array([y]))
        return dict(zip(self.horde.names, forward.prediction[0].tolist(), strict=True))
