"""`check_world`: the environment contract that every world kind keeps, checked through the one interface.

The core's checks take the interface (`horde.core.check.check_source` over a `Source`,
`check_learner_input` over a `Learner`); this module makes them for each kind and adds what only a kind has.

Modelled on Gymnasium's `check_env`. A grid world is checked on both engines by `core/check.py`'s
`check_grid_world`; the kinds fed from outside are checked here.

A Gymnasium world, with a seeded generator and a uniform behaviour:

1. determinism: the same seed gives the same sensors, actions and predictions step by step;
2. sensors: one column per name of `spec.world.sensor_names()`, finite, inside `sensor_bounds()`;
3. endings: `terminated` and `truncated` never both true, truncation only at the time limit, every
   episode ends within it, and the `terminated` / `truncated` sensors read what the environment said;
4. the input path refuses what no world produces: a wrong number of sensors, a NaN, an action out of range.

A stream world: records drawn inside the sensors' ranges are all learned; the same bad records are refused.
"""

from __future__ import annotations

import numpy as np

from horde.core.check import check_grid_world, check_learner_input, check_sensors, check_source, require
from horde.core.horde import Horde
from horde.core.learner import Learner
from horde.spec import BehaviourSpec, GymnasiumWorldSpec, RunSpec, StreamWorldSpec
from horde.worlds.gym_spaces import resolve_world


def _gym_trajectory(spec: RunSpec, seed: int, steps: int) -> list[tuple[np.ndarray, ...]]:
    from horde.worlds.gymnasium import GymAgent

    assert isinstance(spec.world, GymnasiumWorldSpec)
    agent = GymAgent(spec, np.random.default_rng(seed))
    uniform = BehaviourSpec()
    limit = agent.world.env.spec.max_episode_steps if agent.world.env.spec else None
    check_sensors(spec, agent.sensors[None], "gymnasium reset")
    trace: list[tuple[np.ndarray, ...]] = []
    length = 0
    for t in range(1, steps + 1):
        step = agent.step(uniform)
        where = f"gymnasium step {t}"
        sensors = step.sensors  # what the Horde learned from: the sensors after the action
        check_sensors(spec, sensors[None], where)
        require(not (step.terminated and step.truncated), f"{where}: terminated and truncated")
        require(sensors[-2] == float(step.terminated) and sensors[-1] == float(step.truncated),
                 f"{where}: the terminated / truncated sensors disagree with the environment")  # fmt: skip
        length += 1
        if limit is not None:
            require(not step.truncated or length == limit, f"{where}: truncated after {length} steps, not {limit}")
            require(length <= limit, f"{where}: an episode ran past its time limit {limit}")
        if step.done:
            length = 0
            check_sensors(spec, agent.sensors[None], f"{where}: the next episode's first state")
        trace.append((sensors, np.array([step.action]), agent.learner.prediction()))
    check_learner_input(agent.learner, agent.sensors, "gymnasium")
    agent.world.close()
    return trace


def _check_stream(spec: RunSpec, seed: int, steps: int) -> None:
    assert isinstance(spec.world, StreamWorldSpec)
    rng = np.random.default_rng(seed)
    bounds = spec.world.sensor_bounds()
    low = np.array([max(bounds[n][0], -1e3) for n in spec.world.sensor_names()])
    high = np.array([min(bounds[n][1], 1e3) for n in spec.world.sensor_names()])
    sensors = rng.uniform(low, high, size=(steps + 1, len(low)))  # [T + 1, S]
    check_sensors(spec, sensors, "stream records")
    loop = Learner(Horde(spec))
    loop.observe(sensors[0])
    loop.learn(sensors[1:], rng.integers(0, loop.num_actions, steps), np.full(steps, 1.0 / loop.num_actions))
    require(loop.steps == steps, f"stream: {loop.steps} of {steps} records learned")
    check_learner_input(loop, sensors[-1], "stream")


def check_world(spec: RunSpec, seed: int = 0, batch: int = 16, steps: int = 300) -> None:
    """Check the environment contract of `spec`'s world, of any kind (see the module); raise if broken.

    Args:
        spec: a validated run spec (its demons are needed to build the compiled loop).
        seed: the generator's seed; the check is itself deterministic.
        batch: a grid world's episodes run side by side on world.py, each to its end.
        steps: steps replayed (grid), taken (Gymnasium) or records learned (stream).

    Raises:
        WorldCheckError: the world broke the contract (the message says which rule, at which step).
    """
    if spec.world.kind == "grid":
        check_grid_world(spec, seed, batch, steps)
        return
    spec = resolve_world(spec)
    if isinstance(spec.world, StreamWorldSpec):
        _check_stream(spec, seed, steps)
        return
    from horde.worlds.gym_simulation import GymSimulation

    check_source(lambda s: GymSimulation(spec, np.random.default_rng(s)), seed, min(steps, 100))
    first = _gym_trajectory(spec, seed, steps)
    second = _gym_trajectory(spec, seed, steps)
    for t, (a, b) in enumerate(zip(first, second, strict=True)):
        require(all(np.array_equal(x, y) for x, y in zip(a, b, strict=True)),
                 f"gymnasium step {t + 1}: same seed, other run")  # fmt: skip
