"""`Source`: what a run steps, whatever its world: an agent, its world and its Horde learning through one `Learner`.

The grid world's `Simulation` (`simulation.py`) steps its world inside the compiled loop; a Gymnasium agent
(`horde.worlds.gym_simulation.GymSimulation`) steps an environment in Python and feeds the learner. Both
read, save and restore through the members written here once; each writes only how it acts (`run`), where
its world stands (`world_state`), how it swaps its demons (`with_spec`) and what its summary predicts at.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any

import numpy as np

from horde.core.engine.engine import AdaptiveState
from horde.core.engine.layout import FOREVER
from horde.core.horde import Horde, HordeState
from horde.core.learner import Learner, Readout
from horde.spec import BehaviourSpec, RunSpec


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


class Source(ABC):
    """An agent, its world and its Horde (see the module). Not thread-safe: the run manager owns one per run.

    Attributes:
        spec: the run spec (a Gymnasium world's sensors resolved).
        rng: the run's generator.
        learner: the demons learning (`Learner`: observe, learn, readout, state, load).
        episode, total_steps: episodes ended and steps taken so far.
    """

    spec: RunSpec
    rng: np.random.Generator
    learner: Learner
    episode: int
    total_steps: int

    # ------------------------------------------------------------------------------------------
    # What each source writes

    @abstractmethod
    def run(self, max_steps: int, max_episodes: int = FOREVER, behaviour: BehaviourSpec | None = None,
            learning: np.ndarray | None = None) -> StepResult:  # fmt: skip
        """Step until `max_steps` steps or until `max_episodes` episodes have ended; return the last step.

        Args:
            behaviour: overrides the run's behaviour (test runs use a greedy one).
            learning: [D] bool, which demons learn (default all).
        """

    @property
    @abstractmethod
    def world_state(self) -> Any:
        """Where the world stands (arrays only: a snapshot's leaves)."""

    @world_state.setter
    @abstractmethod
    def world_state(self, state: Any) -> None: ...

    @abstractmethod
    def with_spec(self, spec: RunSpec) -> Source:
        """The same agent under a changed set of demons: demons kept keep their weights (`Horde.carry_over`),
        traces restart where the agent stands."""

    @abstractmethod
    def summary_predictions(self) -> dict[str, float]:
        """Each demon's prediction where a run's summary reads it (the grid: the start point; elsewhere the
        agent's state)."""

    # ------------------------------------------------------------------------------------------
    # Written once

    @property
    def horde(self) -> Horde:
        return self.learner.horde

    @property
    def with_metrics(self) -> bool:
        """Whether steps update RUPEE and UDE (protocols leave them out)."""
        return self.learner.with_metrics

    @with_metrics.setter
    def with_metrics(self, on: bool) -> None:
        self.learner.with_metrics = on

    @property
    def horde_state(self) -> HordeState:
        """The Horde's state (a copy)."""
        return self.learner.engine.horde_state()

    @horde_state.setter
    def horde_state(self, state: HordeState) -> None:
        self.learner.engine.load(state)

    def learner_state(self) -> AdaptiveState:
        """Copies of what the true online, emphatic, adaptive and regularised learners keep beyond `horde_state`:
        the per-weight step sizes of autostep and tidbd demons among them (snapshots keep it, so a restored run
        goes on tuned)."""
        return self.learner.engine.adaptive_state()

    def load_learner_state(self, state: AdaptiveState) -> None:
        """Copy a `learner_state()` of a source of the same spec back into the engine."""
        self.learner.engine.load_adaptive_state(state)

    def view_state(self) -> HordeState:
        """A copy for readers (value maps, policies, predictions): the state with the primary weights, and
        without the secondary weights, traces and RUPEE's arrays (empty tuples), a fifth of the copy."""
        return self.learner.engine.horde_state(weights_only=True)

    @property
    def sensors(self) -> np.ndarray:
        """[S] the sensors at the agent's state after the last step (a copy; names in spec.world.sensor_names)."""
        return self.learner.sensors

    @property
    def episode_return(self) -> float:
        """The return of the episode under way."""
        return float(self.learner.engine.t.agent.returns[0])

    @property
    def last_return(self) -> float:
        """The return of the last finished episode."""
        return float(self.learner.engine.t.agent.returns[1])

    def set_returns(self, episode_return: float, last_return: float) -> None:
        """Restore the return of the episode under way and of the last finished one (snapshots)."""
        self.learner.engine.t.agent.returns[:] = (episode_return, last_return)

    def readout(self) -> Readout:
        """What the run layer records every step or so, in O(D) (no weights are copied)."""
        return self.learner.readout()

    def thetas(self) -> list[np.ndarray]:
        """Copies of every block's primary weights [n_b, Db] (the stopping rule compares them)."""
        return self.learner.engine.thetas()

    def step_sizes(self, name: str) -> np.ndarray:
        """[n] the step size of each of one demon's weights now (adaptive demons tune them online)."""
        return self.learner.engine.step_sizes(name)

    def effective_step_sizes(self) -> np.ndarray:
        """[D] each demon's step size at the agent's state, in alpha's units (`Engine.effective_step_sizes`)."""
        return self.learner.engine.effective_step_sizes()

    def prediction_array(self) -> np.ndarray:
        """[D] every demon's prediction at the agent's state (a copy, in demon order)."""
        return self.learner.prediction()

    def predictions(self) -> dict[str, float]:
        return dict(zip(self.horde.names, self.learner.prediction().tolist(), strict=True))

    def _carry_over(self, old: Source) -> None:
        """This source's learner takes the weights (`Horde.carry_over`) and the per-weight step sizes of every
        demon `old` also had, in the same learner and step-size mode and on as many weights."""
        engine, old_engine = self.learner.engine, old.learner.engine
        engine.load(self.horde.carry_over(old.horde, old.horde_state))
        for name in self.horde.names:
            if name not in old.horde.index:
                continue
            (b, col), (ob, ocol) = self.horde.locate(name), old.horde.locate(name)
            mode = self.horde.blocks[b].step_size
            if mode == "constant" or old.horde.blocks[ob].step_size != mode:
                continue
            if self.horde.block_rows[b] != old.horde.block_rows[ob]:
                continue
            slot = int(self.horde.demon_slot[self.horde.index[name]])
            old_slot = int(old.horde.demon_slot[old.horde.index[name]])
            onl, old_onl = engine.t.onl, old_engine.t.onl
            engine.weights(onl.step_a, b)[:, col] = old_engine.weights(old_onl.step_a, ob)[:, ocol] * old_onl.scale[
                old_slot]  # fmt: skip
            engine.weights(onl.step_v, b)[:, col] = old_engine.weights(old_onl.step_v, ob)[:, ocol]
            onl.scale[slot] = 1.0
        engine.count_step_max()
