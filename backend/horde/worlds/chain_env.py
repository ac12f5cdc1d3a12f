"""The Gymnasium environments of the chain worlds (`horde.worlds.chains` names, models and registers them).

Each keeps its state's number in `unwrapped.state` (a one-element float array, the snapshot format's leaf),
so that snapshots and Monte-Carlo rollouts can put it back; `step` reads it there.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from horde.worlds.chains import BOYAN_STATES, MAX_CHAIN_STATES


class _Chain(gym.Env[np.int64, np.int64]):
    """One action, a discrete state numbered as the book numbers it, terminal states included."""

    def __init__(self, observations: int, first: int) -> None:
        self.metadata = {"render_modes": []}
        self.observation_space = spaces.Discrete(observations)
        self.action_space = spaces.Discrete(1)
        self.first = first
        self.state = np.array([float(first)])

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.int64, dict[str, Any]]:
        super().reset(seed=seed)
        self.state = np.array([float(self.first)])
        return np.int64(self.first), {}

    def _move(self) -> tuple[int, float, bool]:
        raise NotImplementedError

    def step(self, action: np.int64) -> tuple[np.int64, float, bool, bool, dict[str, Any]]:
        if int(action) != 0:
            raise ValueError(f"action {action!r}: a chain has one action, 0")
        state, reward, terminated = self._move()
        self.state = np.array([float(state)])
        return np.int64(state), reward, terminated, False, {}


class RandomWalkEnv(_Chain):
    """The random walk over states 1..`states` (0 and states + 1 end it), from the middle, jumping 1 to `jump`
    states left or right uniformly (Sutton & Barto 2018, examples 6.2, 7.1 and 9.1)."""

    def __init__(self, states: int = 19, jump: int = 1, left_reward: float = -1.0, right_reward: float = 1.0) -> None:
        if not 3 <= states <= MAX_CHAIN_STATES:
            raise ValueError(f"states must be 3 to {MAX_CHAIN_STATES}, not {states}")
        if not 1 <= jump <= states:
            raise ValueError(f"jump must be 1 to the number of states, not {jump}")
        super().__init__(states + 2, (states + 1) // 2)
        self.states, self.jump = states, jump
        self.rewards = (float(left_reward), float(right_reward))

    def _move(self) -> tuple[int, float, bool]:
        step = int(self.np_random.integers(1, self.jump + 1)) * (1 if self.np_random.random() < 0.5 else -1)
        state = min(max(int(self.state[0]) + step, 0), self.states + 1)
        if state == 0:
            return 0, self.rewards[0], True
        if state == self.states + 1:
            return state, self.rewards[1], True
        return state, 0.0, False


class BoyanChainEnv(_Chain):
    """Boyan's chain: from 12 down to 0, one or two states a step (-3), from 1 to the end (-2)."""

    def __init__(self) -> None:
        super().__init__(BOYAN_STATES + 1, BOYAN_STATES)

    def _move(self) -> tuple[int, float, bool]:
        state = int(self.state[0])
        if state <= 1:
            return 0, -2.0, True
        state -= 1 if self.np_random.random() < 0.5 else 2
        return state, -3.0, state == 0
