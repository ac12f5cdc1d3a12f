"""One agent in one world with its Horde: the loop that the protocol, the CLI, the server and the bench drive.

There is one engine (`fast.py`: the compiled world and the block learners of `scale_fast.py`, DESIGN
section 6); `Simulation` is its Python face. It is the only mutable object of the core and is not
thread-safe: the run manager owns one per run.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from horde.core import threads
from horde.core.adaptive_kernels import OnlineArrays
from horde.core.fast import (
    FOREVER,
    R_ACTION,
    R_BPROB,
    R_EPISODES,
    R_REWARD,
    R_SIGN,
    R_STEPS,
    R_TERMINATED,
    R_TRUNCATED,
    FastLoop,
)
from horde.core.horde import Horde, HordeState
from horde.core.scale import TRACE_CUT
from horde.core.scale_fast import PARALLEL_MIN
from horde.core.world import World, WorldState
from horde.spec import BehaviourSpec, RunSpec


class AdaptiveState(NamedTuple):
    """The state of `adaptive_kernels.OnlineArrays` that changes as demons learn (in the engine's layout)."""

    v_old: np.ndarray  # [D] true online learners: theta_{t-1} . x_t
    cls_f: np.ndarray  # [C] emphatic TD's followon trace per class
    cls_rho_prev: np.ndarray  # [C] rho_{t-1} per class
    trace2: np.ndarray  # true online GTD's second and third traces
    step_a: np.ndarray  # per-weight step sizes of autostep / tidbd demons (before their scale)
    step_v: np.ndarray  # autostep's normaliser v per weight
    ascale: np.ndarray  # [D] the scale of each demon's step sizes

    @classmethod
    def copy_of(cls, onl: OnlineArrays) -> AdaptiveState:
        """Copies of these arrays of a loop's `onl`."""
        return cls(*(getattr(onl, name).copy() for name in cls._fields))

    def load_into(self, onl: OnlineArrays) -> None:
        """Copy these arrays back into a loop's `onl` (of a loop of the same spec)."""
        for name, array in zip(self._fields, self, strict=True):
            getattr(onl, name)[...] = array


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


class Readout(NamedTuple):
    """Per-demon numbers of the agent's state, in demon order (copies)."""

    prediction: np.ndarray  # [D]
    cumulant: np.ndarray  # [D] the last cumulant
    delta: np.ndarray  # [D] the last TD error
    rupee: np.ndarray  # [D]
    ude: np.ndarray  # [D]
    diverged: np.ndarray  # [D] bool


class Simulation:
    """The agent, its world and its Horde, with a seeded generator.

    Args:
        spec: the run spec.
        rng: the generator (default: seeded from spec.seed).
        cut: the trace cut (DESIGN section 6; 0 keeps every trace entry and equals reference.py to 1e-9).
    """

    def __init__(self, spec: RunSpec, rng: np.random.Generator | None = None, cut: float = TRACE_CUT) -> None:
        self.spec = spec
        self.cut = cut
        self.world = World(spec.grid)
        self.horde = Horde(spec, cut)
        self.rng = rng if rng is not None else np.random.default_rng(spec.seed)
        self.episode = 0
        self.total_steps = 0
        self.with_metrics = True
        self._threads: int | None = None
        self._parallel = any(b.size >= PARALLEL_MIN for b in self.horde.blocks)
        self._loop = FastLoop(self.horde, self.world)
        self._loop.reset_world(self.rng)

    # ------------------------------------------------------------------------------------------
    # State

    @property
    def horde_state(self) -> HordeState:
        """The Horde's state (a copy)."""
        return self._loop.horde_state()

    @horde_state.setter
    def horde_state(self, state: HordeState) -> None:
        self._loop.load(state, self.world_state)

    def learner_state(self) -> AdaptiveState:
        """Copies of what the true online, emphatic and adaptive learners keep beyond `horde_state`: the per-weight
        step sizes of autostep and tidbd demons among them (snapshots keep it, so a restored run goes on tuned)."""
        return AdaptiveState.copy_of(self._loop.onl)

    def load_learner_state(self, state: AdaptiveState) -> None:
        """Copy a `learner_state()` of a simulation of the same spec back into the engine."""
        state.load_into(self._loop.onl)

    def view_state(self) -> HordeState:
        """A copy for readers (value maps, policies, predictions): the state with the primary weights, and
        without the secondary weights, traces and RUPEE's arrays (empty tuples), a fifth of the copy."""
        return self._loop.horde_state(weights_only=True)

    @property
    def world_state(self) -> WorldState:
        return self._loop.world_state()

    @world_state.setter
    def world_state(self, state: WorldState) -> None:
        self._loop.load(self._loop.horde_state(), state)

    @property
    def position(self) -> tuple[float, float]:
        return float(self._loop.pos[0]), float(self._loop.pos[1])

    @property
    def sensors(self) -> np.ndarray:
        """[S] the sensors at the agent's state after the last step (a copy; names in world.sensor_names)."""
        return self._loop.buf.sensors.copy()

    @property
    def threads(self) -> int:
        """Threads a step uses: 1 unless a block has at least `scale_fast.PARALLEL_MIN` demons; then the
        number set here, or by default this process's share of the cores (`horde.core.threads`)."""
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
        return self._loop.buf.start_sensors.copy()

    @property
    def behaviour_probability(self) -> float:
        """b(a_t | s_t) of the last action taken."""
        return float(self._loop.buf.result[R_BPROB])

    @property
    def episode_return(self) -> float:
        """The return of the episode under way."""
        return float(self._loop.returns[0])

    @property
    def last_return(self) -> float:
        """The return of the last finished episode."""
        return float(self._loop.returns[1])

    def set_returns(self, episode_return: float, last_return: float) -> None:
        """Restore the return of the episode under way and of the last finished one (snapshots)."""
        self._loop.returns[:] = (episode_return, last_return)

    def with_spec(self, spec: RunSpec) -> Simulation:
        """The same agent under a changed set of demons: same world state, generator and counters.

        Every demon that this simulation also has keeps its weights (`Horde.carry_over`); traces
        restart as at an episode start. The generator's state is left exactly as it was.
        """
        rng_state = self.rng.bit_generator.state
        new = Simulation(spec, self.rng, self.cut)  # draws a start: the generator is put back below
        self.rng.bit_generator.state = rng_state
        new._loop.load(new.horde.carry_over(self.horde, self.horde_state), self.world_state)
        new._carry_step_sizes(self)
        new._loop.buf.sensors[:] = self._loop.buf.sensors  # what the sensors read here, for sensor-tiled features
        new._loop.observe()
        new.episode = self.episode
        new.total_steps = self.total_steps
        new.with_metrics = self.with_metrics
        new._threads = self._threads
        new.set_returns(self.episode_return, self.last_return)
        return new

    def _carry_step_sizes(self, old: Simulation) -> None:
        """Adaptive demons that `old` also had, in the same mode and on as many weights, keep their per-weight
        step sizes (and Autostep's normalisers), as `Horde.carry_over` keeps their weights."""
        for name in self.horde.names:
            if name not in old.horde.index:
                continue
            (b, col), (ob, ocol) = self.horde.locate(name), old.horde.locate(name)
            mode = self.horde.blocks[b].step_size
            if mode == "constant" or old.horde.blocks[ob].step_size != mode:
                continue
            if self.horde.block_rows[b] != old.horde.block_rows[ob]:
                continue
            slot, old_slot = (
                int(self.horde.demon_slot[self.horde.index[name]]),
                int(old.horde.demon_slot[old.horde.index[name]]),
            )
            new_onl, old_onl = self._loop.onl, old._loop.onl
            self._loop._weights(new_onl.step_a, b)[:, col] = (
                old._loop._weights(old_onl.step_a, ob)[:, ocol] * old_onl.ascale[old_slot]
            )
            self._loop._weights(new_onl.step_v, b)[:, col] = old._loop._weights(old_onl.step_v, ob)[:, ocol]
            new_onl.ascale[slot] = 1.0

    # ------------------------------------------------------------------------------------------
    # Acting

    def new_episode(self) -> None:
        """Abandon the episode under way and start a new one."""
        self.episode += 1
        self._loop.returns[:] = (0.0, self._loop.returns[0])
        self._loop.reset_world(self.rng)

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
            out = self._loop.run(self.rng, max_steps, max_episodes, behaviour, learning, self.with_metrics,
                                 self._thread_count(joining=False))  # fmt: skip
        finally:
            threads.leave()
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
        return self.run(FOREVER, 1, behaviour, learning)

    # ------------------------------------------------------------------------------------------
    # Reading out

    def thetas(self) -> list[np.ndarray]:
        """Copies of every block's primary weights [n_b, Db] (the stopping rule compares them)."""
        return self._loop.thetas()

    def step_sizes(self, name: str) -> np.ndarray:
        """[n] the step size of each of one demon's weights now (adaptive demons tune them online)."""
        return self._loop.step_sizes(name)

    def effective_step_sizes(self) -> np.ndarray:
        """[D] each demon's step size at the agent's state, in alpha's units (FastLoop.effective_step_sizes)."""
        return self._loop.effective_step_sizes()

    def prediction_array(self) -> np.ndarray:
        """[D] every demon's prediction at the agent's state (a copy, in demon order)."""
        return self._loop.prediction()

    def readout(self) -> Readout:
        """What the run layer records every step or so, in O(D) (no weights are copied)."""
        loop = self._loop
        state = loop.buf
        return Readout(
            prediction=loop.prediction(),
            cumulant=loop._per_demon(state.cumulant),
            delta=loop._per_demon(state.delta),
            rupee=loop.rupee(),
            ude=loop.ude(),
            diverged=loop._per_demon(state.diverged),
        )

    def predictions(self) -> dict[str, float]:
        return dict(zip(self.horde.names, self._loop.prediction().tolist(), strict=True))

    def predictions_at(self, x: float, y: float) -> dict[str, float]:
        """Each demon's prediction at a position, with the current weights (nothing learns); NaN if diverged.

        The engine zeroes a diverged demon's weights (so that demons reading it go on), which would read as a
        prediction of 0: NaN says instead that it has no answer.
        """
        forward = self.horde.forward(self.horde_state, np.array([x]), np.array([y]))
        prediction = np.where(self.horde_state.diverged, np.nan, forward.prediction[0])  # [D]
        return dict(zip(self.horde.names, prediction.tolist(), strict=True))
