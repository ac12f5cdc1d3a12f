"""The truth about a demon's question: Monte-Carlo returns, and exact answers on lattice worlds.

Both freeze the Horde where it stands and follow the demon's own target policy. A question's answer
does not stop where an episode is truncated, so rollouts ignore `max_steps` and run until the
continuation has fallen to zero or until `cap` steps (named in the result).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from horde.core.engine.engine import Engine
from horde.core.horde import Horde, HordeState
from horde.core.questions import Program
from horde.core.rollouts import Question, run_rollouts
from horde.core.world import NUM_ACTIONS, PERPENDICULAR, Transition, World, WorldState

# A rollout whose remaining continuation weight falls to this or below has finished.
WEIGHT_FLOOR = 1e-12
CHUNK_STEPS = 200_000  # steps of rollouts between two questions to `stop` (a few tenths of a second)


class StoppedError(Exception):
    """Monte-Carlo rollouts stopped before the end because their caller said so."""


@dataclass(frozen=True)
class Truth:
    """Monte-Carlo estimate of a demon's answer from one state."""

    mean: float
    stderr: float
    rollouts: int
    cap: int
    capped: int  # rollouts still running at the cap


def _question_program(horde: Horde, name: str) -> Program:
    demon = horde.demons[horde.index[name]]
    sensor_index = {s: i for i, s in enumerate(horde.plan.sensors)}
    return Program([demon.cumulant, demon.outcome, demon.continuation], sensor_index, horde.index)


def monte_carlo(
    horde: Horde,
    state: HordeState,
    name: str,
    start: tuple[float, float],
    rollouts: int,
    cap: int,
    rng: np.random.Generator,
    stop: Callable[[], bool] | None = None,
) -> Truth:
    """Average realised return of demon `name`'s question from `start`, following its target policy.

    The rollouts run one after the other in compiled code (`rollouts.py`), the Horde frozen at `state`
    (its primary weights). The return is accumulated in expectation over the continuation:
    G = sum_t (prod_{j<=t} gamma_j) (r_{t+1} + (1 - gamma_{t+1}) z_{t+1}), which equals the return of a
    random stopping time with P(continue) = gamma and has lower variance.

    With `stop`, the rollouts run in chunks of at most CHUNK_STEPS steps and `stop()` is asked after each
    but the last (the same numbers: the chunks draw from one generator in turn).

    Raises:
        StoppedError: `stop()` said so before the last chunk.
    """
    engine = Engine(horde, World(horde.spec.grid))
    for b in range(len(horde.blocks)):
        engine.weights(engine.t.wts.theta, b)[:] = state.theta[b]
    slot = int(horde.demon_slot[horde.index[name]])
    group = next(g for g, grp in enumerate(horde.groups) if horde.index[name] in grp.demons)
    needed = horde.needs([name])
    wanted = np.array([bool(needed[g.demons].any()) for g in horde.groups], dtype=np.bool_)
    question = Question(slot, group, wanted, float(start[0]), float(start[1]), cap, WEIGHT_FLOOR)
    chunk = rollouts if stop is None else max(1, CHUNK_STEPS // cap)
    parts = []
    capped = 0
    for done in range(0, rollouts, chunk):
        if done and stop is not None and stop():
            raise StoppedError(f"stopped after {done} of {rollouts} rollouts")
        part, part_capped = run_rollouts(engine.t, rng, question, min(chunk, rollouts - done))
        parts.append(part)
        capped += part_capped
    totals = np.concatenate(parts)  # [rollouts]
    stderr = float(totals.std(ddof=1) / np.sqrt(rollouts)) if rollouts > 1 else float("nan")
    return Truth(float(totals.mean()), stderr, rollouts, cap, capped)


@dataclass(frozen=True)
class Lattice:
    """The reachable lattice points of a world whose step divides it."""

    x: np.ndarray  # [N]
    y: np.ndarray  # [N]
    value: np.ndarray  # [N] exact answer at each point


def lattice_points(world: World) -> tuple[np.ndarray, np.ndarray]:
    """All lattice points (multiples of step) that are neither blocked nor terminal."""
    spec = world.spec
    if spec.noise > 0 or len(spec.start) != 2:
        raise ValueError("exact answers need a lattice world: no noise and a start point")
    xs = spec.start[0] % spec.step + np.arange(0.0, spec.width, spec.step)
    ys = spec.start[1] % spec.step + np.arange(0.0, spec.height, spec.step)
    gx, gy = (a.ravel() for a in np.meshgrid(xs[xs < spec.width], ys[ys < spec.height], indexing="ij"))
    blocked = world.blocked(gx, gy) | (world.inside(gx, gy) & world.is_terminal).any(axis=1)
    return gx[~blocked], gy[~blocked]


def exact(horde: Horde, state: HordeState, name: str) -> Lattice:
    """Solve the linear system v = c + P_gamma v of demon `name`'s question under its frozen policy.

    Requires a lattice world (no noise, step divides the world) without indicators, and a question
    that does not read the `steps` sensor.
    """
    world = World(horde.spec.grid)
    if world.num_indicators:
        raise ValueError("exact answers do not cover indicators (their colour is hidden state)")
    demon = horde.index[name]
    discount = horde.demons[demon].discount
    program = _question_program(horde, name)
    xs, ys = lattice_points(world)
    n = len(xs)
    where = {(round(float(a), 6), round(float(b), 6)): i for i, (a, b) in enumerate(zip(xs, ys, strict=True))}
    pi = horde.forward(state, xs, ys, demons=[name]).pi[:, demon]  # [N, A]
    slip = world.spec.slip
    matrix = np.zeros((n, n))
    reward = np.zeros(n)
    for action in range(NUM_ACTIONS):
        outcomes = [(action, 1.0 - slip)]
        if slip > 0:
            outcomes += [(int(PERPENDICULAR[action, 0]), slip / 2), (int(PERPENDICULAR[action, 1]), slip / 2)]
        for moved, probability in outcomes:
            nx, ny, bump = world.move(xs, ys, np.full(n, moved))
            inside = world.inside(nx, ny)
            terminated = (inside & world.is_terminal).any(axis=1)
            colors = np.zeros((n, 0), dtype=np.int64)
            step_reward = np.full(n, world.spec.transient_reward)
            if terminated.any():
                step_reward = step_reward + world._terminal_rewards(inside & world.is_terminal, colors)
            after = WorldState(nx, ny, np.ones(n, dtype=np.int64), colors)
            sensors = world.sensors(after, Transition(step_reward, bump, terminated, np.zeros(n, bool), inside))
            predictions = horde.forward(state, nx, ny, sensors, demons=[name]).prediction
            r, z, gamma = program.evaluate(sensors, predictions).T
            gamma = np.where(terminated, 0.0, np.clip(gamma, 0.0, 1.0) * discount)
            p = pi[:, action] * probability  # [N]
            reward += p * (r + (1.0 - gamma) * z)
            for i in range(n):
                if gamma[i] > 0.0:
                    matrix[i, where[(round(float(nx[i]), 6), round(float(ny[i]), 6))]] += p[i] * gamma[i]
    value = np.linalg.solve(np.eye(n) - matrix, reward)
    return Lattice(xs, ys, value)
