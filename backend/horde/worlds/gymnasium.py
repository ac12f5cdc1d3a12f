"""A Gymnasium environment as a Horde world, and an agent that learns on it through the engine's input path.

`GymWorld` steps the real environment in Python and turns what it returns into the sensor vector of
`GymnasiumWorldSpec.sensor_names()`: the observation's components, then `reward`, `terminated` and
`truncated` (all 0 at an episode's first state). Seeding: the first reset takes a seed drawn from the
run's generator; later resets continue the environment's own generator, as Gymnasium intends. Actions
are drawn with the run's generator, so the same seed gives the same run.

`GymAgent` is the loop: the behaviour acts (probabilities b(.|s_t) exact: uniform, fixed, a sign rule or
a policy over a control demon's action values), the environment steps, the Horde learns the transition
(`Learner.learn`), and an ended episode (terminated, or truncated at the time limit) starts afresh.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from horde.core.horde import Horde
from horde.core.learner import Learner
from horde.core.policies import sign_policy
from horde.spec import BehaviourSpec, GymnasiumWorldSpec, PolicySpec, RunSpec
from horde.worlds.gym_spaces import resolve_world


class GymWorld:
    """One Gymnasium environment with a `Box` observation and a `Discrete` action space.

    Args:
        spec: the world spec (validated: the environment is installed and its spaces are supported).
        time_limit: wrap the environment in its time limit (`max_steps`, or the registered one); rollouts
            for Monte-Carlo truth use False, since a question's answer does not stop at truncation.
    """

    def __init__(self, spec: GymnasiumWorldSpec, time_limit: bool = True) -> None:
        import gymnasium as gym

        from horde.worlds.chains import chain_kwargs, register

        register()  # horde/Baird-v0 and the chains

        self.spec = spec
        kwargs = chain_kwargs(spec.id, spec.states)
        if not time_limit:
            self.env: Any = gym.make(spec.id, **kwargs).unwrapped
        elif spec.max_steps is not None:
            self.env = gym.make(spec.id, max_episode_steps=spec.max_steps, **kwargs)
        else:
            self.env = gym.make(spec.id, **kwargs)
        self.sensor_names = spec.sensor_names()
        self.num_actions = spec.num_actions()
        self._obs = len(self.sensor_names) - 3

    def _sensors(self, obs: Any, reward: float, terminated: bool, truncated: bool) -> np.ndarray:
        out = np.empty(self._obs + 3)  # [S]
        out[: self._obs] = np.asarray(obs, dtype=float).reshape(-1)
        out[self._obs :] = (reward, float(terminated), float(truncated))
        return out

    def reset(self, seed: int | None = None) -> np.ndarray:
        """A new episode; returns the sensors at its first state [S]."""
        obs, _ = self.env.reset(seed=seed)
        return self._sensors(obs, 0.0, False, False)

    def step(self, action: int) -> tuple[np.ndarray, bool, bool]:
        """(sensors after the action [S], terminated, truncated)."""
        obs, reward, terminated, truncated, _ = self.env.step(int(action))
        return self._sensors(obs, float(reward), bool(terminated), bool(truncated)), bool(terminated), bool(truncated)

    def get_state(self) -> np.ndarray:
        """The environment's internal state (classic control keeps it in `unwrapped.state`), a copy."""
        return np.array(self.env.unwrapped.state, dtype=float)

    def set_state(self, state: np.ndarray, sensors: np.ndarray) -> None:
        """Put the environment at a state recorded by `get_state` (for rollouts from test states)."""
        self.env.unwrapped.state = np.array(state, dtype=float)

    def close(self) -> None:
        self.env.close()


def policy_probs(policy: PolicySpec | BehaviourSpec, sensors: np.ndarray, names: list[str], num_actions: int,
                 q: np.ndarray | None = None, horde: Horde | None = None) -> np.ndarray:  # fmt: skip
    """[A] probabilities of a uniform, fixed or sign policy at a state (or a value policy, given `horde`, `q`)."""
    if policy.kind == "uniform":
        return np.full(num_actions, 1.0 / num_actions)
    if policy.kind == "fixed" and policy.probabilities is not None:
        return np.asarray(policy.probabilities, dtype=float)
    if policy.kind == "sign" and policy.sensor is not None and policy.actions is not None:
        reading = float(sensors[names.index(policy.sensor)])
        return sign_policy(reading, (policy.actions[0], policy.actions[1]), policy.epsilon, num_actions)
    if horde is not None and q is not None and isinstance(policy, BehaviourSpec):
        return horde.behaviour_probs(q[None], policy)[0]
    raise ValueError(f"a {policy.kind} policy needs the demons' action values")


@dataclass(frozen=True, eq=False)
class GymStep:
    """One step: the action, the reward, how it ended, and the sensors after the action [S]."""

    action: int
    reward: float
    terminated: bool
    truncated: bool
    sensors: np.ndarray

    def same(self, other: GymStep) -> bool:
        return (self.action, self.reward, self.terminated, self.truncated) == (
            other.action, other.reward, other.terminated, other.truncated
        ) and np.array_equal(self.sensors, other.sensors)  # fmt: skip

    @property
    def done(self) -> bool:
        return self.terminated or self.truncated


class GymAgent:
    """The agent on a Gymnasium world: behaviour, environment, and the Horde learning every transition.

    Args:
        spec: a run spec whose world is of kind "gymnasium".
        rng: the run's generator (default: seeded from spec.seed).
        world, sensors: an environment already under way and the sensors at its state (a live run's demons
            changed); default a new environment, reset with a seed drawn from `rng`.
    """

    def __init__(self, spec: RunSpec, rng: np.random.Generator | None = None, *, world: GymWorld | None = None,
                 sensors: np.ndarray | None = None) -> None:  # fmt: skip
        if not isinstance(spec.world, GymnasiumWorldSpec):
            raise ValueError(f"a GymAgent needs a gymnasium world, not {spec.world.kind!r}")
        self.spec = spec = resolve_world(spec)  # its sensors and actions known, the spec checked against them
        self.rng = rng if rng is not None else np.random.default_rng(spec.seed)
        self.world = world if world is not None else GymWorld(spec.world)  # type: ignore[arg-type]
        self.horde = Horde(spec)
        self.learner = Learner(self.horde)
        self.episode = 0
        self.total_steps = 0
        self.returns = self.learner.engine.t.agent.returns  # [2] the episode under way, the last finished one
        if world is not None and sensors is not None:
            self.sensors = np.array(sensors, dtype=float)
        else:
            self.sensors = self.world.reset(seed=int(self.rng.integers(2**31)))
        self.learner.observe(self.sensors)

    def behaviour_probs(self, behaviour: BehaviourSpec | None = None) -> np.ndarray:
        """[A] b(. | s_t) at the agent's state."""
        behaviour = behaviour or self.spec.behaviour
        q = self.learner.q() if behaviour.demon is not None else None
        return policy_probs(behaviour, self.sensors, self.world.sensor_names, self.world.num_actions, q, self.horde)

    def step(self, behaviour: BehaviourSpec | None = None) -> GymStep:
        """Act, step the environment, learn the transition; an ended episode starts afresh."""
        probs = self.behaviour_probs(behaviour)
        action = self._draw(probs)
        sensors, terminated, truncated = self.world.step(action)
        self.learner.learn(sensors, [action], [probs[action]], terminated, truncated)
        reward = float(sensors[-3])
        self.returns[0] += reward
        self.total_steps += 1
        self.sensors = sensors
        if terminated or truncated:
            self.episode += 1
            self.returns[:] = (0.0, self.returns[0])
            self.sensors = self.world.reset()
            self.learner.observe(self.sensors)
        return GymStep(action, reward, terminated, truncated, sensors)

    def run_episode(self) -> int:
        """Step to the end of the episode under way (terminated or truncated); returns the steps taken.

        Under a behaviour that reads no demon (uniform, fixed, sign) the episode's transitions are stepped first
        and learned in one call (the same draws, actions and weights as `step` gives one at a time, several times
        faster: the engine's cost per call is paid once). A value policy reads the demons as they learn: step by
        step."""
        behaviour = self.spec.behaviour
        if behaviour.kind not in ("uniform", "fixed", "sign"):
            episode, steps = self.episode, 0
            while self.episode == episode:
                self.step()
                steps += 1
            return steps
        names, num_actions = self.world.sensor_names, self.world.num_actions
        probs = policy_probs(behaviour, self.sensors, names, num_actions)  # (a sign rule's: drawn again each step)
        rows: list[np.ndarray] = []
        actions: list[int] = []
        taken: list[float] = []
        terminated = truncated = False
        while not (terminated or truncated):
            if rows and behaviour.kind == "sign":
                probs = policy_probs(behaviour, rows[-1], names, num_actions)
            action = self._draw(probs)
            sensors, terminated, truncated = self.world.step(action)
            rows.append(sensors)
            actions.append(action)
            taken.append(probs[action])
        self.learner.learn(np.array(rows), actions, np.array(taken), terminated, truncated)
        rewards = float(np.sum([row[-3] for row in rows]))
        self.total_steps += len(rows)
        self.episode += 1
        self.returns[:] = (0.0, self.returns[0] + rewards)
        self.sensors = self.world.reset()
        self.learner.observe(self.sensors)
        return len(rows)

    def _draw(self, probs: np.ndarray) -> int:
        """An action drawn from `probs` with the run's generator: the one draw of `step` and `run_episode`, so that
        an episode learned in one call takes the actions it would take step by step."""
        action = int(np.searchsorted(np.cumsum(probs), self.rng.random() * probs.sum(), side="right"))
        return min(action, len(probs) - 1)

    def run(self, steps: int, behaviour: BehaviourSpec | None = None) -> None:
        for _ in range(steps):
            self.step(behaviour)

    def predictions(self) -> dict[str, float]:
        return dict(zip(self.horde.names, self.learner.prediction().tolist(), strict=True))
