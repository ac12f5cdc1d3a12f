"""The thesis-scale workload: the whole loop (world, features, policies, learning) of Experiment 1.

`scenarios/experiment1.toml` (the base control demon and `steps_to_end`) plus extra GTD(lambda)
prediction demons that follow the base demon's policy, each with a sensor as cumulant and one of four
continuations, run by `Simulation` without the RUPEE / UDE metrics,
as the protocol runs it. The baseline is `reference.ReferenceHorde` driven through the same world by
its own plain policies (a softmax behaviour over the base demon's action values).
"""

from __future__ import annotations

import time

import numpy as np

from horde.core.reference import ReferenceHorde, value_policy
from horde.core.simulation import Simulation
from horde.core.world import World
from horde.scenarios import load_scenario, scenario_dir
from horde.spec import RunSpec

SENSORS = ("x", "y", "bump", "in:goal", "in:pit", "reward")
CONTINUATIONS = (1.0, 0.9, 0.5, 0.0)


def spec_with(demons: int) -> RunSpec:
    """experiment1 with `demons` demons in all (the two of the scenario plus prediction demons)."""
    base = load_scenario(scenario_dir() / "experiment1.toml")
    data = base.model_dump(by_alias=True)
    extra = [
        {
            "name": f"p{i}",
            "learner": "gtd",
            "policy": {"of": "base"},
            "cumulant": {"sensor": SENSORS[i % len(SENSORS)]},
            "continuation": CONTINUATIONS[i % len(CONTINUATIONS)],
        }
        for i in range(max(demons - len(data["demons"]), 0))
    ]
    data["demons"] = data["demons"][:demons] + extra
    return RunSpec.model_validate(data)


def simulation(demons: int, seed: int = 0) -> Simulation:
    sim = Simulation(spec_with(demons), np.random.default_rng(seed))
    sim.with_metrics = False
    return sim


def reference_seconds_per_step(demons: int, steps: int, seed: int = 0) -> float:
    """Median wall seconds per step of the plain reference Horde (`demons` demons) through the numpy world."""
    spec = spec_with(demons)
    rng = np.random.default_rng(seed)
    world = World(spec.world)
    names = spec.world.sensor_names()
    ref = ReferenceHorde(spec)
    behaviour = spec.behaviour
    state = world.reset(rng, 1)
    ref.observe(float(state.x[0]), float(state.y[0]))
    base = ref.demons[behaviour.demon] if behaviour.demon else None
    seconds = []
    for _ in range(steps):
        start = time.perf_counter()
        if base is None:
            b = np.full(4, 0.25)
        else:
            b = value_policy(
                behaviour.kind, ref.q_values(base, base.phi_state_t), behaviour.temperature, behaviour.epsilon
            )
        action = int(rng.choice(4, p=b))
        state, transition = world.step(state, np.array([action]), rng)
        sensors = dict(zip(names, world.sensors(state, transition)[0].tolist(), strict=True))
        terminated = bool(transition.terminated[0])
        ref.learn(action, float(b[action]), float(state.x[0]), float(state.y[0]), sensors, terminated)
        if terminated or bool(transition.truncated[0]):
            state = world.reset(rng, 1)
            ref.observe(float(state.x[0]), float(state.y[0]))
        seconds.append(time.perf_counter() - start)
    return float(np.median(seconds))
