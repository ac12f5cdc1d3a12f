"""The environment contract, checked through the one interface every world kind keeps (`Source`, `Learner`),
and `check_grid_world`: the grid world's, on both engines.

Modelled on Gymnasium's `check_env`, which runs over every registered environment: this runs over every
scenario (tests/test_scenarios.py) and over any spec a user writes. It checks, with a seeded generator:

1. determinism: the same seed gives the same starts, colours and trajectory (numpy engine, `world.py`);
2. sensors: the vector has one column per name of `spec.sensor_names()`, finite and inside
   `spec.sensor_bounds()`;
3. starts: every drawn start lies inside the world, outside obstacles and terminals;
4. endings: `terminated` and `truncated` are never both true, truncation comes exactly at `max_steps`,
   and every episode ends;
5. the engines agree: the compiled loop (`engine/loop.py`, what `Simulation` runs) and `world.py` give the same
   reward, sensors, ending and next position for the same state and action on a short seeded trajectory.
   The moves are compared without slip and noise (the two engines draw those from the generator in a
   different order, so a stochastic move cannot be replayed); everything else of the world is kept.

Any world kind, through the interface (`horde.worlds.check.check_world` makes the sources and learners):
`check_source` (the same seed gives the same run; every sensor named, finite and in bounds; never
terminated and truncated at once) and `check_learner_input` (the input path refuses what no world
produces: a wrong number of sensors, a NaN, an action out of range, each naming its field).

Each failure raises `WorldCheckError` with what went wrong and where.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from horde.core.learner import ExternalRecordError, Learner
from horde.core.simulation import Simulation
from horde.core.source import Source
from horde.core.world import NUM_ACTIONS, World, WorldState
from horde.spec import RunSpec


class WorldCheckError(AssertionError):
    """A world broke the environment contract (the message says which rule, at which step)."""


def require(ok: bool, message: str) -> None:
    if not ok:
        raise WorldCheckError(message)


def check_sensors(spec: RunSpec, sensors: np.ndarray, where: str) -> None:
    """[B, S] sensors: named as the spec says, finite, within the spec's bounds."""
    names = spec.world.sensor_names()
    require(sensors.shape[-1] == len(names), f"{where}: {sensors.shape[-1]} sensors, the spec names {len(names)}")
    require(bool(np.isfinite(sensors).all()), f"{where}: a sensor is not finite")
    bounds = spec.world.sensor_bounds()
    for column, name in enumerate(names):
        low, high = bounds[name]
        values = sensors[..., column]
        require(
            bool(((values >= low - 1e-9) & (values <= high + 1e-9)).all()),
            f"{where}: sensor {name!r} read {values.min():g}..{values.max():g}, outside [{low:g}, {high:g}]",
        )


def check_source(make: Callable[[int], Source], seed: int, steps: int) -> None:
    """Two sources of one seed (`make(seed)`) step `steps` times with their behaviour: the same actions,
    rewards, endings, sensors and predictions step by step; every sensor named, finite and within its bounds;
    never terminated and truncated at once."""
    one, two = make(seed), make(seed)
    spec = one.spec
    check_sensors(spec, one.sensors[None], "the first state")
    for t in range(1, steps + 1):
        first, second = one.run(1), two.run(1)
        where = f"step {t}"
        require(first == second, f"{where}: same seed, another step ({first} != {second})")
        require(np.array_equal(one.sensors, two.sensors), f"{where}: same seed, other sensors")
        require(np.array_equal(one.prediction_array(), two.prediction_array(), equal_nan=True),
                f"{where}: same seed, other predictions")  # fmt: skip
        check_sensors(spec, one.sensors[None], where)
        require(not (first.terminated and first.truncated), f"{where}: terminated and truncated")


def check_learner_input(learner: Learner, good: np.ndarray, where: str) -> None:
    """The learner's input path refuses records no world produces, each naming its field, and learns none."""
    bad = [
        (np.append(good, 0.0), [0], [1.0], "sensors"),
        (np.where(np.arange(len(good)) == 0, np.nan, good), [0], [1.0], "sensors."),
        (good, [learner.num_actions], [1.0], "action"),
        (good, [0], [0.0], "behaviour_probabilities"),
    ]
    for sensors, action, prob, field in bad:
        steps = learner.steps
        try:
            learner.learn(sensors, action, prob)
        except ExternalRecordError as exc:
            require(str(exc).startswith(field), f"{where}: a bad record was refused without naming {field!r}: {exc}")
        else:
            raise WorldCheckError(f"{where}: a bad record ({field}) was learned")
        require(learner.steps == steps, f"{where}: a refused record ({field}) was counted as learned")


def _check_starts(world: World, state: WorldState, where: str) -> None:
    inside = world.inside(state.x, state.y)
    require(not bool(world.blocked(state.x, state.y).any()), f"{where}: a start is outside the world or in an obstacle")
    require(not bool((inside & world.is_terminal).any()), f"{where}: a start lies in a terminal")
    require(bool((state.steps == 0).all()), f"{where}: a start has steps != 0")


def _numpy_episodes(spec: RunSpec, seed: int, batch: int) -> list[tuple[np.ndarray, ...]]:
    """Run `batch` episodes of random actions to their end with world.py, checking every step."""
    world = World(spec.grid)
    require(world.sensor_names == spec.grid.sensor_names(), "world.py names its sensors unlike the spec")
    rng = np.random.default_rng(seed)
    state = world.reset(rng, batch)
    _check_starts(world, state, "world.py reset")
    check_sensors(spec, world.start_sensors(state), "world.py start sensors")
    trace: list[tuple[np.ndarray, ...]] = [(state.x, state.y, state.colors)]
    ended = np.zeros(batch, dtype=bool)
    for t in range(1, spec.grid.max_steps + 1):
        actions = rng.integers(0, NUM_ACTIONS, size=batch)
        state, transition = world.step(state, actions, rng)
        where = f"world.py step {t}"
        check_sensors(spec, world.sensors(state, transition), where)
        require(not bool((transition.terminated & transition.truncated).any()), f"{where}: terminated and truncated")
        require(bool((transition.truncated == (state.steps == spec.grid.max_steps) & ~transition.terminated).all()),
                 f"{where}: truncated other than at max_steps")  # fmt: skip
        require(not bool(world.blocked(state.x, state.y).any()), f"{where}: moved into an obstacle or out of the world")
        trace.append((state.x, state.y, transition.reward, transition.terminated))
        ended |= transition.terminated | transition.truncated
        if ended.all():
            return trace
    raise WorldCheckError(f"world.py: an episode did not end within max_steps = {spec.grid.max_steps}")


def _check_engines_agree(spec: RunSpec, seed: int, steps: int) -> None:
    """Replay each step of the compiled loop on world.py (moves without slip and noise, see the module)."""
    exact_world = spec.grid.model_copy(update={"slip": 0.0, "noise": 0.0})
    exact = spec.model_copy(update={"world": exact_world})
    sim = Simulation(exact, np.random.default_rng(seed))
    world = World(exact_world)
    require(len(sim.sensors) == len(spec.world.sensor_names()), "the compiled loop has another number of sensors")
    dummy = np.random.default_rng(0)  # world.py draws nothing without slip and noise
    for t in range(1, steps + 1):
        before = sim.world_state
        if before.steps[0] == 0:
            _check_starts(world, before, f"compiled start before step {t}")
        result = sim.step()
        state, transition = world.step(before, np.array([result.action]), dummy)
        where = f"step {t} (action {result.action} from ({before.x[0]:g}, {before.y[0]:g}))"
        require(bool(transition.terminated[0]) == result.terminated, f"{where}: the engines disagree on terminated")
        require(bool(transition.truncated[0]) == result.truncated, f"{where}: the engines disagree on truncated")
        require(np.isclose(transition.reward[0], result.reward), f"{where}: the engines disagree on the reward")
        np_sensors = world.sensors(state, transition)[0]
        if not np.allclose(np_sensors, sim.sensors):
            names = [
                n for n, a, b in zip(world.sensor_names, np_sensors, sim.sensors, strict=True) if not np.isclose(a, b)
            ]
            raise WorldCheckError(f"{where}: the engines disagree on sensors {names}")
        if not result.done:
            require(np.allclose(sim.position, (state.x[0], state.y[0])), f"{where}: the engines disagree on the move")


def check_grid_world(spec: RunSpec, seed: int = 0, batch: int = 16, steps: int = 300) -> None:
    """Check the environment contract of `spec`'s grid world on both engines (see the module); raise if broken.

    Args:
        spec: a validated run spec (its demons are needed to build the compiled loop).
        seed: the generator's seed; the check is itself deterministic.
        batch: episodes run side by side on world.py, each to its end.
        steps: steps of the compiled loop replayed on world.py.
    """
    first = _numpy_episodes(spec, seed, batch)
    second = _numpy_episodes(spec, seed, batch)
    for t, (a, b) in enumerate(zip(first, second, strict=True)):
        require(
            all(np.array_equal(x, y) for x, y in zip(a, b, strict=True)), f"world.py step {t}: same seed, other run"
        )
    require(len(first) == len(second), "world.py: same seed, episodes of other lengths")
    _check_engines_agree(spec, seed, steps)
    check_source(lambda s: Simulation(spec, np.random.default_rng(s)), seed, min(steps, 100))
