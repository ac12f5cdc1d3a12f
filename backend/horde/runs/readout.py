"""Reading a run's knowledge without disturbing it: value maps and Monte-Carlo evaluations of a view.

What a run's world allows (`evaluation_support`): on the grid, rollouts from any point [x, y] and a value map
over the world; on a Gymnasium world, rollouts from the agent's current state in a copy of the environment
(the same rollouts as `horde run`'s, `worlds.protocol.rollout_returns`), no value map; on a stream nothing to
roll out in.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal, Protocol

import numpy as np

from horde.core.evaluate import Truth, exact, monte_carlo
from horde.core.horde import Horde, HordeState
from horde.core.world import World, WorldState
from horde.runs.errors import NotFoundError, SpecError
from horde.spec import GymnasiumWorldSpec, RunSpec, WorldSpec, expr_predictions
from horde.worlds.gym_simulation import GymWorldState
from horde.worlds.gymnasium import GymWorld
from horde.worlds.protocol import rollout_returns
from horde.worlds.state_values import model_of, values_report


class Readable(Protocol):
    """What a readout reads of a run: its weights, frozen or live (`worker.Readable`, in the run's worker)."""

    @property
    def id(self) -> str: ...
    @property
    def spec(self) -> RunSpec: ...
    @property
    def horde(self) -> Horde: ...
    @property
    def horde_state(self) -> HordeState: ...
    @property
    def world_state(self) -> WorldState | GymWorldState: ...
    @property
    def total_steps(self) -> int: ...


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


EvaluationKind = Literal["grid", "rollouts", "none"]
GIVEN_POLICIES = ("uniform", "fixed", "sign")  # target policies a rollout in a Gymnasium copy can follow
# Rollout steps (episodes x cap) of one evaluation on a Gymnasium world, at most: stepped in Python at about
# 10,000 steps a second, this bounds an evaluation to some twenty seconds (the grid's compiled rollouts need none).
MAX_ROLLOUT_STEPS = 200_000


@dataclass(frozen=True)
class EvaluationSupport:
    """What a Monte-Carlo evaluation can be in a run's world, and a sentence saying so (or why there is none)."""

    kind: EvaluationKind
    note: str


GRID_NOTE = (
    "Monte-Carlo rollouts of the demon's target policy from a point [x, y] (default: the world's start, the centre "
    "of a start rectangle), beside its prediction there; the value map shows it over the world"
)
ROLLOUTS_NOTE = (
    "Monte-Carlo rollouts of the demon's target policy from the agent's current state, in a copy of the environment "
    "without its time limit, beside its prediction there; no value map over the world, and none for a demon whose "
    "target policy reads action values or whose question reads other demons"
)
STREAM_NOTE = (
    "a stream's records come from outside, so there is no copy of its world to roll a target policy out in; "
    "`horde run --log` compares a log's predictions with its realised returns instead"
)


def evaluation_support(spec: RunSpec) -> EvaluationSupport:
    """ "grid": from a point, with a value map; "rollouts": from the current state, no value map; "none": why not."""
    if isinstance(spec.world, WorldSpec):
        return EvaluationSupport("grid", GRID_NOTE)
    if isinstance(spec.world, GymnasiumWorldSpec):
        return EvaluationSupport("rollouts", ROLLOUTS_NOTE)
    return EvaluationSupport("none", STREAM_NOTE)


@dataclass(frozen=True)
class Evaluation:
    """A demon's prediction at a state and the Monte-Carlo truth of its question there.

    `start` is the point [x, y] on the grid, the sensors at the state the rollouts began from elsewhere.
    """

    demon: str
    start: tuple[float, ...]
    prediction: float
    truth: Truth
    seed: int
    step: int  # the run's step whose weights were evaluated
    exact: float | None = None  # the exact answer at `start`, on a lattice world that has one


def _demon_index(view: Readable, name: str) -> int:
    if name not in view.horde.index:
        raise NotFoundError(f"run {view.id!r} has no demon {name!r}")
    return view.horde.index[name]


def value_map(view: Readable, name: str, resolution: int) -> ValueMap:
    """The demon's prediction over the world on a resolution x resolution grid, with frozen weights."""
    demon = _demon_index(view, name)
    if view.spec.world.kind != "grid":
        kind, note = view.spec.world.kind, evaluation_support(view.spec).note
        raise SpecError.at(("path", "run_id"), f"a value map over the world needs the grid world; this run's world "
                                               f"is a {kind} one: {note}")  # fmt: skip
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


def state_values(view: Readable, name: str) -> dict[str, object] | None:
    """The demon's prediction at every state of a world with known transitions (the chains, Baird's star), beside
    the exact values, the TD fixed point and the errors (`horde.worlds.state_values.values_report`); None on any
    other world."""
    _demon_index(view, name)
    if model_of(view.horde.spec) is None:
        return None
    with np.errstate(all="ignore"):
        return values_report(view.horde, view.horde_state, [name])[name]


def evaluate(
    view: Readable,
    name: str,
    start: tuple[float, float] | None,
    episodes: int,
    cap: int,
    seed: int | None = None,
    stop: Callable[[], bool] | None = None,
) -> Evaluation:
    """Roll the demon's target policy out `episodes` times (at most `cap` steps each), as the world allows
    (`evaluation_support`): on the grid from `start` (default: the world's start), on a Gymnasium world from
    the agent's current state (`start` must be left out).

    The rollouts use their own generator (seeded from `seed`, by default from the run's seed and
    step count), so an evaluation never changes the run's own random stream.

    Raises:
        NotFoundError: an unknown demon.
        SpecError: a start outside the world or inside an obstacle, or given where the world has no points
            (naming the field `from`); a demon whose question rollouts cannot follow (naming `demon`); a world
            with nothing to roll out in (naming `run_id`).
        StoppedError: `stop()` said so before the grid's rollouts were done (`core.evaluate.monte_carlo`; a
            Gymnasium world's rollouts are bounded by MAX_ROLLOUT_STEPS instead).
    """
    demon = _demon_index(view, name)
    seed = seed if seed is not None else int(view.spec.seed * 1_000_003 + view.total_steps) % 2**63
    support = evaluation_support(view.spec)
    if support.kind == "rollouts":
        if start is not None:
            raise SpecError.at(("body", "from"), "this run's world has no points: its demons are evaluated from the "
                                                 "agent's current state; leave `from` out")  # fmt: skip
        return _evaluate_rollouts(view, name, demon, episodes, cap, seed)
    if support.kind == "none":
        raise SpecError.at(("path", "run_id"), f"no Monte-Carlo evaluation here: {support.note}")
    x, y = start if start is not None else _start_point(view.spec.grid)
    world = World(view.spec.grid)
    if not view.spec.grid.contains(x, y):
        raise SpecError.at(
            ("body", "from"), f"({x}, {y}) lies outside the world [0, {world.width}) x [0, {world.height})"
        )
    inside = world.inside(np.array([x]), np.array([y]))[0]  # [R]
    blocked = [world.region_names[r] for r in np.nonzero(inside & world.is_obstacle)[0]]
    if blocked:
        raise SpecError.at(("body", "from"), f"({x}, {y}) lies inside obstacle {blocked[0]!r}")
    rng = np.random.default_rng(seed)
    prediction = float(
        view.horde.forward(view.horde_state, np.array([x]), np.array([y]), demons=[name]).prediction[0, demon]
    )
    if view.horde_state.diverged[demon]:
        prediction = math.nan  # reported as null, as everywhere else
    truth = monte_carlo(view.horde, view.horde_state, name, (x, y), episodes, cap, rng, stop)
    return Evaluation(name, (x, y), prediction, truth, seed, view.total_steps, exact_at(view, name, (x, y)))


def _start_point(world: WorldSpec) -> tuple[float, float]:
    """The world's start point, or the centre of its start rectangle (as the dashboard's `startPoint`)."""
    start = world.start
    if len(start) >= 4:
        return (start[0] + start[2]) / 2, (start[1] + start[3]) / 2
    return start[0], start[1]


def _evaluate_rollouts(view: Readable, name: str, demon: int, episodes: int, cap: int, seed: int) -> Evaluation:
    """The demon's prediction now and the mean realised return of rollouts from the agent's current state."""
    spec, state = view.spec, view.world_state
    if episodes * cap > MAX_ROLLOUT_STEPS:
        raise SpecError.at(("body", "episodes"), f"{episodes} rollouts of up to {cap} steps exceed the "
                                                 f"{MAX_ROLLOUT_STEPS:,} steps one evaluation may take on a Gymnasium "
                                                 "world: ask for fewer episodes or a smaller cap")  # fmt: skip
    question = spec.demons[demon]
    if question.policy.kind not in GIVEN_POLICIES or any(
        expr_predictions(e) for e in (question.cumulant, question.outcome, question.continuation)
    ):
        raise SpecError.at(("body", "demon"), f"demon {name!r} has no Monte-Carlo truth here: its target policy "
                                              f"({question.policy.kind}) reads action values, or its question reads "
                                              "other demons' predictions")  # fmt: skip
    assert isinstance(spec.world, GymnasiumWorldSpec) and isinstance(state, GymWorldState)
    if len(state.env_state) == 0:  # rollouts start from a copy of `unwrapped.state` (classic control keeps one)
        raise SpecError.at(("path", "run_id"), f"{spec.world.id!r} keeps no state (`unwrapped.state`) that rollouts "
                                               "could start from")  # fmt: skip
    world = GymWorld(spec.world, time_limit=False)
    try:
        world.reset(seed=seed % 2**32)
        returns, capped = rollout_returns(spec, world, state.env_state, state.sensors, [demon], episodes, cap,
                                          np.random.default_rng(seed))  # fmt: skip
    finally:
        world.close()
    returns = returns[:, 0]  # [episodes]
    stderr = float(returns.std(ddof=1) / math.sqrt(len(returns))) if len(returns) > 1 else math.nan
    diverged = bool(view.horde_state.diverged[demon])
    prediction = math.nan if diverged else float(view.horde_state.prediction[demon])
    truth = Truth(float(returns.mean()), stderr, len(returns), cap, capped)
    return Evaluation(name, tuple(float(s) for s in state.sensors), prediction, truth, seed, view.total_steps)


def exact_at(view: Readable, name: str, point: tuple[float, float]) -> float | None:
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
