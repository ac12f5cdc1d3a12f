"""A Gymnasium agent as a source a live run steps: `GymSimulation`, the grid `Simulation`'s twin.

A live run (`horde.runs.session`) steps a source of transitions through one interface (`horde.core.source.
Source`): `run` some steps, read the Horde's state, swap the demons (`with_spec`), freeze and restore. The
grid world's `Simulation` is one source; this is another, a `GymAgent` (the environment stepped in Python,
the Horde learning each transition through its `Learner`). What the grid keeps in a `WorldState` (the
agent's position), a Gymnasium world keeps in a `GymWorldState`: the environment's internal state, the steps
of the episode under way, the sensors there, and the environment's own generator, so that a restored run
goes on bit for bit. Snapshots need an environment that keeps its state in `unwrapped.state` (every
classic-control one does); others run, but cannot be restored (`GymStateError`: such a run comes back failed,
saying why).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from horde.core.engine.layout import FOREVER
from horde.core.source import Source, StepResult
from horde.spec import BehaviourSpec, RunSpec
from horde.worlds.gymnasium import GymAgent

_WORD = (1 << 32) - 1


class GymStateError(ValueError):
    """The environment keeps no `unwrapped.state` to save and restore."""


class GymWorldState(NamedTuple):
    """What a Gymnasium world needs to go on exactly: arrays only (the snapshot format's leaves)."""

    env_state: np.ndarray  # [k] the environment's `unwrapped.state`
    steps: np.ndarray  # [1] int: transitions so far in the episode under way (its time limit counts them)
    sensors: np.ndarray  # [S] the sensors at the agent's state
    env_rng: np.ndarray  # [10] int: the environment's PCG64 state (see `_rng_words`)


def _rng_words(state: dict) -> np.ndarray:
    """[10] int64: a PCG64 state's two 128-bit numbers as four 32-bit words each, has_uint32, uinteger."""
    words = [(int(state["state"][key]) >> (32 * i)) & _WORD for key in ("state", "inc") for i in range(4)]
    return np.array([*words, int(state["has_uint32"]), int(state["uinteger"])], dtype=np.int64)


def _rng_state(words: np.ndarray) -> dict:
    value = [int(w) & _WORD for w in words]
    number = [sum(value[4 * k + i] << (32 * i) for i in range(4)) for k in range(2)]
    return {"bit_generator": "PCG64", "state": {"state": number[0], "inc": number[1]},
            "has_uint32": value[8], "uinteger": value[9]}  # fmt: skip


class GymSimulation(Source):
    """The agent on a Gymnasium world, stepped by a live run.

    Args:
        spec: a run spec whose world is of kind "gymnasium".
        rng: the run's generator (default: seeded from spec.seed).
        agent: the agent to wrap (`with_spec` hands the environment over; default a new one).
    """

    def __init__(self, spec: RunSpec, rng: np.random.Generator | None = None, agent: GymAgent | None = None) -> None:
        self.agent = agent if agent is not None else GymAgent(spec, rng)
        self.spec = self.agent.spec  # its world's sensors resolved (`horde.worlds.gym_spaces.resolve_world`)
        self.rng = self.agent.rng
        self.learner = self.agent.learner

    @property
    def episode(self) -> int:
        return self.agent.episode

    @episode.setter
    def episode(self, value: int) -> None:
        self.agent.episode = value

    @property
    def total_steps(self) -> int:
        return self.agent.total_steps

    @total_steps.setter
    def total_steps(self, value: int) -> None:
        self.agent.total_steps = value

    @property
    def world_state(self) -> GymWorldState:
        """The environment's state (env_state empty for one that keeps none in `unwrapped.state`: restoring
        that raises GymStateError)."""
        env = self.agent.world.env
        state = getattr(env.unwrapped, "state", None)
        state = np.zeros(0) if state is None else state
        steps = env.get_wrapper_attr("_elapsed_steps") if hasattr(env, "get_wrapper_attr") else 0
        return GymWorldState(
            env_state=np.array(state, dtype=float).reshape(-1),
            steps=np.array([int(steps or 0)], dtype=np.int64),
            sensors=self.sensors,
            env_rng=_rng_words(env.unwrapped.np_random.bit_generator.state),
        )

    @world_state.setter
    def world_state(self, state: GymWorldState) -> None:
        """Put the environment back at a saved state.

        Raises:
            GymStateError: the environment keeps no `unwrapped.state`, so none was saved.
        """
        env = self.agent.world.env
        if len(state.env_state) == 0:
            raise GymStateError(f"{getattr(self.spec.world, 'id', '')!r} keeps no state that a snapshot could hold; "
                                "the run cannot go on from one")  # fmt: skip
        env.unwrapped.state = np.array(state.env_state, dtype=float)
        env.unwrapped.np_random.bit_generator.state = _rng_state(state.env_rng)
        if hasattr(env, "set_wrapper_attr"):
            env.set_wrapper_attr("_elapsed_steps", int(state.steps[0]))
        self.agent.sensors = np.array(state.sensors, dtype=float)
        self.learner.engine.t.agent.sensors[:] = state.sensors

    @property
    def episode_step(self) -> int:
        env = self.agent.world.env
        return int(env.get_wrapper_attr("_elapsed_steps") or 0) if hasattr(env, "get_wrapper_attr") else 0

    def with_spec(self, spec: RunSpec) -> GymSimulation:
        """The same agent and environment under a changed set of demons; demons kept keep their weights,
        traces restart at the current state (as `Simulation.with_spec`)."""
        old = self.agent
        agent = GymAgent(spec, old.rng, world=old.world, sensors=old.sensors)
        new = GymSimulation(spec, agent=agent)
        new._carry_over(self)
        agent.learner.observe(old.sensors)
        agent.episode, agent.total_steps = old.episode, old.total_steps
        new.set_returns(self.episode_return, self.last_return)
        new.with_metrics = self.with_metrics
        return new

    def run(self, max_steps: int, max_episodes: int = FOREVER, behaviour: BehaviourSpec | None = None,
            learning: np.ndarray | None = None) -> StepResult:  # fmt: skip
        """Step until `max_steps` steps or until `max_episodes` episodes have ended; return the last step."""
        agent = self.agent
        if learning is not None:
            agent.learner.set_learning(learning)
        ended, last = 0, None
        try:
            for _ in range(max_steps):
                last = agent.step(behaviour)
                if last.done:
                    ended += 1
                    if ended >= max_episodes:
                        break
        finally:
            if learning is not None:
                agent.learner.set_learning(None)
        if last is None:
            return StepResult(-1, 0.0, False, False, 0.0)
        return StepResult(last.action, last.reward, last.terminated, last.truncated, 0.0)

    def summary_predictions(self) -> dict[str, float]:
        """Each demon's prediction at the agent's state."""
        return self.predictions()
