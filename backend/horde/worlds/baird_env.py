"""The Gymnasium environment of Baird's star (`horde.worlds.baird` names it and registers it): one class.

Seven states: six upper ones (0 to 5) and a lower one (6). Two actions: `dashed` (0) moves to one of the
six upper states, uniformly; `solid` (1) moves to the lower state. Reward 0, nothing terminates. The
observation is the state's number (`Discrete(7)`), kept in `unwrapped.state` for snapshots and rollouts.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from horde.worlds.baird import DASHED, SOLID, UPPER


class BairdEnv(gym.Env[np.int64, np.int64]):
    """The seven-state star of Baird's counterexample: dashed to a uniform upper state, solid to the lower one."""

    def __init__(self) -> None:
        self.metadata = {"render_modes": []}
        self.observation_space = spaces.Discrete(UPPER + 1)
        self.action_space = spaces.Discrete(2)
        self.state = np.zeros(1)  # [1] the state's number, as a float (the snapshot format's leaves)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.int64, dict[str, Any]]:
        """Start in one of the seven states, uniformly (the behaviour's own distribution over them)."""
        super().reset(seed=seed)
        state = np.int64(self.np_random.integers(UPPER + 1))
        self.state = np.array([float(state)])
        return state, {}

    def step(self, action: np.int64) -> tuple[np.int64, float, bool, bool, dict[str, Any]]:
        if int(action) not in (DASHED, SOLID):
            raise ValueError(f"action {action!r} is not 0 (dashed) or 1 (solid)")
        state = np.int64(UPPER if int(action) == SOLID else self.np_random.integers(UPPER))
        self.state = np.array([float(state)])
        return state, 0.0, False, False, {}
