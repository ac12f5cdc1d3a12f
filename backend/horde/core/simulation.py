"""One agent in the grid world with its Horde: the source that the protocol, the CLI, the server and the bench drive.

The world moves inside the compiled loop (`engine.loop.run`: the grid world compiled, then every demon's
learning step); the rest of the interface (state in and out, readout, divergence) is every source's
(`source.Source`, over `learner.Learner`).
"""

from __future__ import annotations

import numpy as np

from horde.core import threads
from horde.core.engine.blocks import TRACE_CUT
from horde.core.engine.engine import AdaptiveState
from horde.core.engine.layout import FOREVER, PARALLEL_MIN
from horde.core.engine.loop import R_ACTION, R_BPROB, R_EPISODES, R_REWARD, R_SIGN, R_STEPS, R_TERMINATED, R_TRUNCATED
from horde.core.horde import Horde
from horde.core.learner import Learner, Readout
from horde.core.source import Source, StepResult
from horde.core.world import World, WorldState
from horde.spec import BehaviourSpec, RunSpec

__all__ = ["AdaptiveState", "Readout", "Simulation", "StepResult"]


class Simulation(Source):
    """The agent, its grid world and its Horde, with a seeded generator.

    Args:
        spec: the run spec.
        rng: the generator (default: seeded from spec.seed).
        cut: the trace cut (DESIGN section 6; 0 keeps every trace entry and equals reference.py to 1e-9).
    """

    def __init__(self, spec: RunSpec, rng: np.random.Generator | None = None, cut: float = TRACE_CUT) -> None:
        self.spec = spec
        self.cut = cut
        self.world = World(spec.grid)
        self.learner = Learner(Horde(spec, cut), self.world)
        self.rng = rng if rng is not None else np.random.default_rng(spec.seed)
        self.episode = 0
        self.total_steps = 0
        self._threads: int | None = None
        self._parallel = any(b.size >= PARALLEL_MIN for b in self.horde.blocks)
        self.learner.engine.reset_world(self.rng)

    # ------------------------------------------------------------------------------------------
    # State

    @property
    def world_state(self) -> WorldState:
        return self.learner.engine.world_state()

    @world_state.setter
    def world_state(self, state: WorldState) -> None:
        self.learner.engine.set_world_state(state)

    @property
    def position(self) -> tuple[float, float]:
        pos = self.learner.engine.t.agent.pos
        return float(pos[0]), float(pos[1])

    @property
    def threads(self) -> int:
        """Threads a step uses: 1 unless a block has at least `PARALLEL_MIN` demons; then the number set
        here, or by default this process's share of the cores (`horde.core.threads`)."""
        return self._thread_count(joining=True)

    @threads.setter
    def threads(self, count: int | None) -> None:
        """Set the threads of this simulation's steps (None: the process's share, which follows the runs)."""
        self._threads = None if count is None else max(1, int(count))

    def _thread_count(self, joining: bool) -> int:
        """Threads for a step; joining: as if this run started learning now (else it is counted already)."""
        if not self._parallel:
            return 1
        return self._threads if self._threads is not None else threads.share(1 if joining else 0)

    @property
    def start_sensors(self) -> np.ndarray:
        """[S] the sensors at the state the Horde last observed afresh (the episode's first state; a copy)."""
        return self.learner.engine.t.agent.start_sensors.copy()

    @property
    def behaviour_probability(self) -> float:
        """b(a_t | s_t) of the last action taken."""
        return float(self.learner.engine.t.agent.result[R_BPROB])

    def with_spec(self, spec: RunSpec) -> Simulation:
        """The same agent under a changed set of demons: same world state, generator and counters.

        Every demon that this simulation also has keeps its weights (`Horde.carry_over`) and its per-weight
        step sizes; traces restart as at an episode start. The generator's state is left exactly as it was.
        """
        rng_state = self.rng.bit_generator.state
        new = Simulation(spec, self.rng, self.cut)  # draws a start: the generator is put back below
        self.rng.bit_generator.state = rng_state
        new._carry_over(self)
        new.world_state = self.world_state
        engine = new.learner.engine
        engine.t.agent.sensors[:] = self.learner.engine.t.agent.sensors  # what the sensors read here
        engine.observe()
        new.episode = self.episode
        new.total_steps = self.total_steps
        new.with_metrics = self.with_metrics
        new._threads = self._threads
        new.set_returns(self.episode_return, self.last_return)
        return new

    # ------------------------------------------------------------------------------------------
    # Acting

    def new_episode(self) -> None:
        """Abandon the episode under way and start a new one."""
        self.episode += 1
        self.set_returns(0.0, self.episode_return)
        self.learner.engine.reset_world(self.rng)

    def step(self, behaviour: BehaviourSpec | None = None, learning: np.ndarray | None = None) -> StepResult:
        """Act with the behaviour policy, learn from the transition, and start a new episode when it ends.

        Args:
            behaviour: overrides the run's behaviour (test runs use a greedy one).
            learning: [D] bool, which demons learn (default all).
        """
        return self.run(1, behaviour=behaviour, learning=learning)

    def run(
        self,
        max_steps: int,
        max_episodes: int = FOREVER,
        behaviour: BehaviourSpec | None = None,
        learning: np.ndarray | None = None,
    ) -> StepResult:
        """Step until `max_steps` steps or until `max_episodes` episodes have ended; return the last step."""
        threads.enter()  # counted as running while it learns: runs share the process's cores (threads.share)
        try:
            out = self.learner.engine.run(self.rng, max_steps, max_episodes, behaviour, learning, self.with_metrics,
                                          self._thread_count(joining=False))  # fmt: skip
        finally:
            threads.leave()
        self.total_steps += int(out[R_STEPS])
        self.episode += int(out[R_EPISODES])
        self.learner.learned(int(out[R_STEPS]))
        return StepResult(
            int(out[R_ACTION]),
            float(out[R_REWARD]),
            bool(out[R_TERMINATED]),
            bool(out[R_TRUNCATED]),
            float(out[R_SIGN]),
        )

    def run_episode(self, behaviour: BehaviourSpec | None = None, learning: np.ndarray | None = None) -> StepResult:
        """Step until the current episode ends; return its last step."""
        return self.run(FOREVER, 1, behaviour, learning)

    # ------------------------------------------------------------------------------------------
    # Reading out

    def predictions_at(self, x: float, y: float) -> dict[str, float]:
        """Each demon's prediction at a position, with the current weights (nothing learns); NaN if diverged.

        The engine zeroes a diverged demon's weights (so that demons reading it go on), which would read as a
        prediction of 0: NaN says instead that it has no answer.
        """
        state = self.view_state()
        forward = self.horde.forward(state, np.array([x]), np.array([y]))
        prediction = np.where(state.diverged, np.nan, forward.prediction[0])  # [D]
        return dict(zip(self.horde.names, prediction.tolist(), strict=True))

    def summary_predictions(self) -> dict[str, float]:
        """Each demon's prediction at the world's start point (the centre of a start rectangle)."""
        start = self.spec.grid.start
        point = ((start[0] + start[2]) / 2, (start[1] + start[3]) / 2) if len(start) >= 4 else (start[0], start[1])
        return self.predictions_at(*point)
