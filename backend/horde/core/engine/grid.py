"""The grid world compiled (DESIGN section 2): starts, moves, walls, terminals, sensors, as `world.World` steps them.

The world owns no random state: every draw takes the caller's generator, in `World.step`'s order (slip, then
noise). The loop (`loop.py`) and the Monte-Carlo rollouts (`rollouts.py`) move the agent with `move`.
"""

from __future__ import annotations

from numba import njit

from horde.core.engine.layout import NO_NRT
from horde.core.world import DIRECTIONS, PERPENDICULAR, START_DRAWS, ImpossibleStartError
from horde.spec import IMPOSSIBLE_START

DIRECTIONS_ = DIRECTIONS.copy()
PERPENDICULAR_ = PERPENDICULAR.astype("int64")


@njit(**NO_NRT)
def holds(rects, r, x, y):
    """Region r's rectangle holds (x, y): x0 <= x < x1 and y0 <= y < y1."""
    return rects[r, 0] <= x and x < rects[r, 2] and rects[r, 1] <= y and y < rects[r, 3]


@njit(**NO_NRT)
def blocked(world, x, y):
    """Whether (x, y) is outside the world or inside an obstacle."""
    if x < 0.0 or x >= world.width or y < 0.0 or y >= world.height:
        return True
    for r in range(world.rects.shape[0]):  # noqa: SIM110 (numba compiles loops, not any() over generators)
        if world.is_obstacle[r] and holds(world.rects, r, x, y):
            return True
    return False


@njit(**NO_NRT)
def draw(rng, cdf, n):
    """An index drawn from the cumulative weights cdf[:n] with one uniform (the last index if rounding leaves the
    draw past every bound): how the behaviour and the Monte-Carlo rollouts pick an action."""
    u = rng.random() * cdf[n - 1]
    index = 0
    for a in range(n):
        if u >= cdf[a]:
            index += 1
    return min(index, n - 1)


@njit(**NO_NRT)
def displacement(rng, world, action):
    """The (dx, dy) an action moves the agent: to a perpendicular with probability slip (half each way), one
    step long, plus Gaussian noise on each axis (random draws in this order, as `World.step` makes them)."""
    moved = action
    if world.slip > 0.0:
        u = rng.random()
        if u < world.slip:
            moved = PERPENDICULAR_[action, 1 if u < world.slip / 2 else 0]
    dx = DIRECTIONS_[moved, 0] * world.step
    dy = DIRECTIONS_[moved, 1] * world.step
    if world.noise > 0.0:
        dx = dx + rng.normal(0.0, world.noise)
        dy = dy + rng.normal(0.0, world.noise)
    return dx, dy


@njit(**NO_NRT)
def _bad_start(world, x, y):
    if blocked(world, x, y):
        return True
    for r in range(world.rects.shape[0]):  # noqa: SIM110 (numba compiles loops, not any() over generators)
        if world.is_terminal[r] and holds(world.rects, r, x, y):
            return True
    return False


@njit(cache=True)
def reset(rng, world, agent):
    """An episode starts: a start drawn (a point, or uniformly from a rectangle outside obstacles and terminals),
    steps 0, every indicator's colour drawn.

    Raises:
        ImpossibleStartError: no start found in START_DRAWS draws (the spec refuses such a world first)."""
    pos = agent.pos
    if world.start_rect:
        for n in range(START_DRAWS + 1):
            if n == START_DRAWS:
                raise ImpossibleStartError(IMPOSSIBLE_START)
            pos[0] = world.start[0] + (world.start[2] - world.start[0]) * rng.random()
            pos[1] = world.start[1] + (world.start[3] - world.start[1]) * rng.random()
            if not _bad_start(world, pos[0], pos[1]):
                break
    else:
        pos[0] = world.start[0]
        pos[1] = world.start[1]
    agent.steps[0] = 0
    for i in range(world.color_count.shape[0]):
        u = rng.random()
        c = 0
        while c < world.color_count[i] and world.color_cdf[i, c] <= u:
            c += 1
        agent.colors[i] = min(c, world.color_count[i] - 1)


@njit(**NO_NRT)
def start_sensors(world, agent):
    """The sensors at an episode's first state, into agent.start_sensors: no move yet, so bump, steps, reward
    and terminal are 0."""
    num_regions = world.rects.shape[0]
    sensors = agent.start_sensors
    sensors[:5] = 0.0
    sensors[0] = agent.pos[0]
    sensors[1] = agent.pos[1]
    for r in range(num_regions):
        sensors[5 + r] = 1.0 if holds(world.rects, r, agent.pos[0], agent.pos[1]) else 0.0
    for i in range(world.ind_region.shape[0]):
        inside = holds(world.rects, world.ind_region[i], agent.pos[0], agent.pos[1])
        sensors[5 + num_regions + i] = world.color_values[i, agent.colors[i]] if inside else 0.0
    sensors[sensors.shape[0] - 1] = 0.0


@njit(**NO_NRT)
def move(rng, world, agent, action):
    """The agent takes `action`: it moves (a blocked move leaves it where it was, bump 1), the regions holding it,
    a terminal's reward, the step count and agent.sensors at the new state (DESIGN section 2's order).

    Returns (the reward, whether it terminated, the terminal reward)."""
    pos, inside, sensors = agent.pos, agent.inside, agent.sensors
    dx, dy = displacement(rng, world, action)
    nx = pos[0] + dx
    ny = pos[1] + dy
    bump = 0.0
    if blocked(world, nx, ny):
        nx = pos[0]
        ny = pos[1]
        bump = 1.0
    num_regions = world.rects.shape[0]
    terminated = False
    terminal = 0.0
    for r in range(num_regions):
        inside[r] = holds(world.rects, r, nx, ny)
        if inside[r] and world.is_terminal[r] and not terminated:
            terminated = True
            terminal = world.term_table[r, agent.colors[world.term_ind[r]]] if world.term_ind[r] >= 0 else (
                world.term_reward[r])  # fmt: skip
    reward = world.transient + terminal
    agent.steps[0] += 1
    pos[0] = nx
    pos[1] = ny
    sensors[0] = nx
    sensors[1] = ny
    sensors[2] = bump
    sensors[3] = float(agent.steps[0])
    sensors[4] = reward
    for r in range(num_regions):
        sensors[5 + r] = 1.0 if inside[r] else 0.0
    num_indicators = world.ind_region.shape[0]
    for i in range(num_indicators):
        sensors[5 + num_regions + i] = world.color_values[i, agent.colors[i]] if inside[world.ind_region[i]] else 0.0
    sensors[5 + num_regions + num_indicators] = 1.0 if terminated else 0.0
    return reward, terminated, terminal
