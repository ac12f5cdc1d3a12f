"""The continuous grid world of the thesis, vectorized over a batch of agents.

One `World` is compiled from a `WorldSpec` and is immutable. The state of a batch of B agents is a
`WorldState` of arrays with a leading batch axis; `step` returns a new state and never changes its
argument. The world owns no random state: every function that draws takes the caller's seeded
`numpy.random.Generator`, so the same seed gives the same run.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from horde.spec import IMPOSSIBLE_START, IndicatorReward, WorldSpec

UP, DOWN, LEFT, RIGHT = 0, 1, 2, 3
NUM_ACTIONS = 4
# Unit moves per action: up (+y), down (-y), left (-x), right (+x).
DIRECTIONS = np.array([[0.0, 1.0], [0.0, -1.0], [-1.0, 0.0], [1.0, 0.0]])
# The two perpendicular actions of each action (where a slip goes).
PERPENDICULAR = np.array([[LEFT, RIGHT], [LEFT, RIGHT], [UP, DOWN], [UP, DOWN]])


START_DRAWS = 1000  # draws of a start point before an engine gives up (both engines)


class ImpossibleStartError(ValueError):
    """No start point could be drawn outside obstacles and terminals (the spec rejects such a world)."""


class WorldState(NamedTuple):
    """The state of B agents, each in its own episode."""

    x: np.ndarray  # [B] float
    y: np.ndarray  # [B] float
    steps: np.ndarray  # [B] int: transitions so far in this episode
    colors: np.ndarray  # [B, I] int: colour index of each indicator, drawn at episode start


class Transition(NamedTuple):
    """What one step produced, besides the next state."""

    reward: np.ndarray  # [B] transient plus terminal reward
    bump: np.ndarray  # [B] 1.0 where the move was blocked
    terminated: np.ndarray  # [B] bool: entered a terminal region
    truncated: np.ndarray  # [B] bool: reached max_steps without terminating
    inside: np.ndarray  # [B, R] bool: which regions hold the next position


class World:
    """A compiled `WorldSpec`: arrays of regions, colours and rewards."""

    def __init__(self, spec: WorldSpec) -> None:
        self.spec = spec
        self.width = float(spec.width)
        self.height = float(spec.height)
        regions = spec.regions
        self.region_names = [r.name for r in regions]
        self.rects = np.array([r.rect for r in regions], dtype=float).reshape(-1, 4)  # [R, 4]
        kinds = np.array([r.kind for r in regions], dtype=object)
        self.is_obstacle = kinds == "obstacle"  # [R]
        self.is_terminal = kinds == "terminal"  # [R]
        self.indicator_regions = [i for i, r in enumerate(regions) if r.kind == "indicator"]
        indicator_slot = {regions[i].name: slot for slot, i in enumerate(self.indicator_regions)}
        self.color_names = [[c.name for c in regions[i].colors or []] for i in self.indicator_regions]
        self.color_values = [np.array([c.value for c in regions[i].colors or []]) for i in self.indicator_regions]
        self.color_probs = [np.array([c.probability for c in regions[i].colors or []]) for i in self.indicator_regions]
        # Terminal rewards: a constant, or a table over one indicator's colours.
        num_regions = len(regions)
        max_colors = max((len(v) for v in self.color_values), default=1)
        self.terminal_reward = np.zeros(num_regions)  # [R]
        self.terminal_indicator = np.full(num_regions, -1)  # [R] indicator slot or -1
        self.terminal_table = np.zeros((num_regions, max_colors))  # [R, C]
        for i, region in enumerate(regions):
            if isinstance(region.reward, IndicatorReward):
                slot = indicator_slot[region.reward.indicator]
                self.terminal_indicator[i] = slot
                for c, name in enumerate(self.color_names[slot]):
                    self.terminal_table[i, c] = region.reward.values[name]
            elif region.reward is not None:
                self.terminal_reward[i] = float(region.reward)
        self.sensor_names = spec.sensor_names()
        self.sensor_index = {name: i for i, name in enumerate(self.sensor_names)}
        start = np.asarray(spec.start, dtype=float)
        self.start_point = start[:2] if len(start) == 2 else None
        self.start_rect = start if len(start) == 4 else None

    # ------------------------------------------------------------------------------------------

    @property
    def num_indicators(self) -> int:
        return len(self.indicator_regions)

    def inside(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Which regions hold each point: [B, R] bool (x0 <= x < x1 and y0 <= y < y1)."""
        r = self.rects
        return (
            (r[None, :, 0] <= x[:, None])
            & (x[:, None] < r[None, :, 2])
            & (r[None, :, 1] <= y[:, None])
            & (y[:, None] < r[None, :, 3])
        )

    def blocked(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """[B] bool: outside the rectangle or inside an obstacle."""
        outside = (x < 0) | (x >= self.width) | (y < 0) | (y >= self.height)
        if not self.is_obstacle.any():
            return outside
        return outside | (self.inside(x, y) & self.is_obstacle).any(axis=1)

    def move(
        self, x: np.ndarray, y: np.ndarray, actions: np.ndarray, offset: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Deterministic move of `step` in each action's direction (plus an optional offset).

        Returns:
            (x_tp1, y_tp1, bump): the agent stays where it was, with bump 1, if the end point is blocked.
        """
        delta = DIRECTIONS[actions] * self.spec.step  # [B, 2]
        if offset is not None:
            delta = delta + offset
        nx, ny = x + delta[:, 0], y + delta[:, 1]
        bump = self.blocked(nx, ny)
        return np.where(bump, x, nx), np.where(bump, y, ny), bump.astype(float)

    def reset(self, rng: np.random.Generator, batch: int = 1) -> WorldState:
        """B fresh episodes: start positions and indicator colours drawn with `rng`."""
        if self.start_point is not None:
            x = np.full(batch, self.start_point[0])
            y = np.full(batch, self.start_point[1])
        else:
            x, y = self._draw_start(rng, batch)
        colors = np.zeros((batch, self.num_indicators), dtype=np.int64)
        for slot, probs in enumerate(self.color_probs):
            colors[:, slot] = rng.choice(len(probs), size=batch, p=probs)
        return WorldState(x=x, y=y, steps=np.zeros(batch, dtype=np.int64), colors=colors)

    def _draw_start(self, rng: np.random.Generator, batch: int) -> tuple[np.ndarray, np.ndarray]:
        assert self.start_rect is not None
        x0, y0, x1, y1 = self.start_rect
        x, y = np.empty(batch), np.empty(batch)
        todo = np.arange(batch)
        for _ in range(START_DRAWS):
            x[todo] = rng.uniform(x0, x1, size=len(todo))
            y[todo] = rng.uniform(y0, y1, size=len(todo))
            bad = self.blocked(x[todo], y[todo]) | (self.inside(x[todo], y[todo]) & self.is_terminal).any(axis=1)
            todo = todo[bad]
            if len(todo) == 0:
                return x, y
        raise ImpossibleStartError(IMPOSSIBLE_START)

    def step(self, state: WorldState, actions: np.ndarray, rng: np.random.Generator) -> tuple[WorldState, Transition]:
        """One transition for every agent: slip, noise, blocking, rewards, termination, truncation."""
        actions = np.asarray(actions, dtype=np.int64)
        batch = len(actions)
        if self.spec.slip > 0.0:
            u = rng.random(batch)  # [B]
            slipped = u < self.spec.slip
            side = (u < self.spec.slip / 2).astype(np.int64)
            actions = np.where(slipped, PERPENDICULAR[actions, side], actions)
        offset = rng.normal(0.0, self.spec.noise, size=(batch, 2)) if self.spec.noise > 0.0 else None
        x, y, bump = self.move(state.x, state.y, actions, offset)
        inside = self.inside(x, y)  # [B, R]
        in_terminal = inside & self.is_terminal  # [B, R]
        terminated = in_terminal.any(axis=1)
        reward = np.full(batch, self.spec.transient_reward)
        if terminated.any():
            reward = reward + self._terminal_rewards(in_terminal, state.colors)
        steps = state.steps + 1
        truncated = (steps >= self.spec.max_steps) & ~terminated
        next_state = WorldState(x=x, y=y, steps=steps, colors=state.colors)
        return next_state, Transition(reward, bump, terminated, truncated, inside)

    def _terminal_rewards(self, in_terminal: np.ndarray, colors: np.ndarray) -> np.ndarray:
        """[B] reward of the first terminal region holding each agent (0 where none)."""
        first = np.argmax(in_terminal, axis=1)  # [B]
        hit = in_terminal.any(axis=1)
        reward = self.terminal_reward[first].copy()
        slot = self.terminal_indicator[first]  # [B]
        by_color = slot >= 0
        if by_color.any():
            rows = np.nonzero(by_color)[0]
            color = colors[rows, slot[rows]]
            reward[rows] = self.terminal_table[first[rows], color]
        return np.where(hit, reward, 0.0)

    def terminal_sign(self, state: WorldState, inside: np.ndarray) -> np.ndarray:
        """[B] +1 / -1 / 0: the sign of the terminal reward where an agent stands (for test counts)."""
        in_terminal = inside & self.is_terminal
        return np.sign(self._terminal_rewards(in_terminal, state.colors))

    def sensors(self, state: WorldState, transition: Transition) -> np.ndarray:
        """The sensor vector of each agent after a transition: [B, S], names in `sensor_names`."""
        columns = [
            state.x,
            state.y,
            transition.bump,
            state.steps.astype(float),
            transition.reward,
        ]
        inside = transition.inside.astype(float)  # [B, R]
        color_columns = [
            np.where(transition.inside[:, region], self.color_values[slot][state.colors[:, slot]], 0.0)
            for slot, region in enumerate(self.indicator_regions)
        ]
        return np.column_stack([*columns, inside, *color_columns, transition.terminated.astype(float)])  # [B, S]

    def start_sensors(self, state: WorldState) -> np.ndarray:
        """Sensors at an episode's first state (no transition yet: bump, reward and terminal are 0)."""
        batch = len(state.x)
        zeros = np.zeros(batch)
        transition = Transition(zeros, zeros, zeros.astype(bool), zeros.astype(bool), self.inside(state.x, state.y))
        return self.sensors(state, transition)
