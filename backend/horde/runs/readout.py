"""Reading a run's knowledge without disturbing it: value maps and Monte-Carlo evaluations of a view."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from horde.core.evaluate import Truth, exact, monte_carlo
from horde.core.world import World
from horde.runs.errors import NotFoundError, SpecError
from horde.runs.run_view import RunView

# Positions x demons x actions evaluated in one batch of a value map (bounds its memory).
MAX_BATCH_NUMBERS = 2_000_000
# The exact answer solves a dense system over the lattice points: beyond this many, Monte-Carlo only.
MAX_EXACT_POINTS = 2_500


def cell_centres(width: float, height: float, resolution: int) -> tuple[np.ndarray, np.ndarray]:
    """xs [N] and ys [N]: the centres of an N x N grid over [0, width) x [0, height), N = `resolution`.

    The grid of every value map, greedy-action map and arrow field: cell (i, j) is centred at (xs[i], ys[j]),
    and a map's entry [j, i] is its value there (row j grows with y).
    """
    xs = (np.arange(resolution) + 0.5) * width / resolution  # [N]
    ys = (np.arange(resolution) + 0.5) * height / resolution  # [N]
    return xs, ys


@dataclass(frozen=True)
class ValueMap:
    """A demon's prediction at the centres of an N x N grid over the world."""

    xs: np.ndarray  # [N] cell centres along x
    ys: np.ndarray  # [N] cell centres along y
    values: np.ndarray  # [N, N]: values[j, i] is the prediction at (xs[i], ys[j])


@dataclass(frozen=True)
class Evaluation:
    """A demon's prediction at a point and the Monte-Carlo truth of its question there."""

    demon: str
    start: tuple[float, float]
    prediction: float
    truth: Truth
    seed: int
    exact: float | None = None  # the exact answer at `start`, on a lattice world that has one


def _require_grid(view: RunView, loc: tuple[str, ...], what: str) -> None:
    """Raises SpecError (422 at `loc`) for a run whose world is not the grid: `what` needs positions."""
    if view.spec.world.kind != "grid":
        raise SpecError.at(loc, f"{what} needs the grid world; this run's world is a {view.spec.world.kind} one "
                                "(the live view draws its demons' values over a phase plane of two sensors, and "
                                "`horde run` compares its predictions with realised returns)")  # fmt: skip


def _demon_index(view: RunView, name: str) -> int:
    if name not in view.horde.index:
        raise NotFoundError(f"run {view.id!r} has no demon {name!r}")
    return view.horde.index[name]


def value_map(view: RunView, name: str, resolution: int) -> ValueMap:
    """The demon's prediction over the world on a resolution x resolution grid, with frozen weights."""
    demon = _demon_index(view, name)
    _require_grid(view, ("path", "run_id"), "a value map over the world")
    world = view.spec.grid
    xs, ys = cell_centres(world.width, world.height, resolution)  # [N] each
    gx, gy = np.meshgrid(xs, ys)  # [N, N] each, rows along y
    px, py = gx.ravel(), gy.ravel()  # [N * N]
    batch = max(1, MAX_BATCH_NUMBERS // (4 * max(1, view.horde.num_demons)))
    values = np.empty(len(px))
    for begin in range(0, len(px), batch):
        end = begin + batch
        values[begin:end] = view.horde.forward(
            view.horde_state, px[begin:end], py[begin:end], demons=[name]
        ).prediction[:, demon]
    return ValueMap(xs, ys, values.reshape(resolution, resolution))


def evaluate(
    view: RunView,
    name: str,
    start: tuple[float, float],
    episodes: int,
    cap: int,
    seed: int | None = None,
    stop: Callable[[], bool] | None = None,
) -> Evaluation:
    """Roll the demon's target policy out `episodes` times from `start` (at most `cap` steps each).

    The rollouts use their own generator (seeded from `seed`, by default from the run's seed and
    step count), so an evaluation never changes the run's own random stream.

    Raises:
        NotFoundError: an unknown demon.
        SpecError: a start outside the world or inside an obstacle (naming the field `from`).
        StoppedError: `stop()` said so before the rollouts were done (`core.evaluate.monte_carlo`).
    """
    demon = _demon_index(view, name)
    _require_grid(view, ("body", "from"), "a Monte-Carlo evaluation from a point")
    x, y = start
    world = World(view.spec.grid)
    if not view.spec.grid.contains(x, y):
        raise SpecError.at(
            ("body", "from"), f"({x}, {y}) lies outside the world [0, {world.width}) x [0, {world.height})"
        )
    inside = world.inside(np.array([x]), np.array([y]))[0]  # [R]
    blocked = [world.region_names[r] for r in np.nonzero(inside & world.is_obstacle)[0]]
    if blocked:
        raise SpecError.at(("body", "from"), f"({x}, {y}) lies inside obstacle {blocked[0]!r}")
    seed = seed if seed is not None else int(view.spec.seed * 1_000_003 + view.total_steps) % 2**63
    rng = np.random.default_rng(seed)
    prediction = float(
        view.horde.forward(view.horde_state, np.array([x]), np.array([y]), demons=[name]).prediction[0, demon]
    )
    if view.horde_state.diverged[demon]:
        prediction = math.nan  # reported as null, as everywhere else
    truth = monte_carlo(view.horde, view.horde_state, name, (x, y), episodes, cap, rng, stop)
    return Evaluation(name, (x, y), prediction, truth, seed, exact_at(view, name, (x, y)))


def exact_at(view: RunView, name: str, point: tuple[float, float]) -> float | None:
    """The exact answer of the demon's question at `point` under its frozen policy, where one exists.

    That is on a small lattice world (no noise, no indicators, at most MAX_EXACT_POINTS lattice points,
    `point` one of them) for a question that does not read the `steps` sensor (`core.evaluate.exact`).
    """
    world = view.spec.grid
    if (world.width / world.step) * (world.height / world.step) > MAX_EXACT_POINTS:
        return None
    if '"sensor":"steps"' in view.horde.demon_specs[view.horde.index[name]].model_dump_json():
        return None
    try:
        lattice = exact(view.horde, view.horde_state, name)
    except ValueError:
        return None  # not a lattice world
    at = np.nonzero((np.abs(lattice.x - point[0]) < 1e-6) & (np.abs(lattice.y - point[1]) < 1e-6))[0]
    return float(lattice.value[at[0]]) if len(at) else None
