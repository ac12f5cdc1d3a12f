"""The vectorized engine (Simulation -> Horde -> learners) equals the plain ReferenceHorde to 1e-9.

The numpy engine's transitions are recorded as they reach `Horde.learn` and `Horde.start_episode` and
fed, one by one, to `reference.ReferenceHorde`; after every step every demon's weights, secondary
weights, traces, prediction and target policy must agree (DESIGN section 6). A compiled engine, if the
simulation has one, runs in lockstep with the recorded numpy simulation of the same seed: it must take
the same transitions and agree with the reference just as closely.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from horde.core.reference import ReferenceHorde
from horde.core.simulation import Simulation
from horde.spec import RunSpec

from .engines import NUMPY_ENGINE, new_simulation

TOLERANCE = 1e-9

DEMONS: list[dict[str, Any]] = [
    # control demons (GQ over their own action values)
    {
        "name": "base",
        "policy": {"kind": "softmax", "temperature": 0.5},
        "cumulant": {"sensor": "reward"},
        "lambda": 0.8,
        "alpha": 0.2,
        "alpha_w": 0.01,
    },
    {
        "name": "greedy_ctl",
        "policy": "greedy",
        "cumulant": -0.01,
        "outcome": {"sensor": "in:goal"},
        "discount": 0.95,
        "lambda": 0.5,
    },
    {
        "name": "eps_ctl",
        "policy": {"kind": "epsilon_greedy", "epsilon": 0.2},
        "cumulant": {"sensor": "bump"},
        "continuation": 0.9,
        "features": {"kind": "tiles", "tilings": 4, "tiles": 4},
    },
    # prediction demons
    {
        "name": "steps",
        "learner": "gtd",
        "policy": {"of": "base"},
        "cumulant": 1,
        "lambda": 0.9,
        "alpha": 0.05,
    },
    {"name": "goal_prob", "policy": "uniform", "outcome": {"sensor": "in:goal"}, "lambda": 0.7},
    {
        "name": "bumps",
        "learner": "td",
        "policy": {"kind": "fixed", "probabilities": [0.4, 0.1, 0.1, 0.4]},
        "cumulant": {"sensor": "bump"},
        "discount": 0.8,
        "lambda": 0.5,
    },
    {
        "name": "pass_crit",
        "learner": "gtd",
        "policy": {"of": "base"},
        "outcome": {"sensor": "in:crit"},
        "continuation": {"if": {"sensor": "in:crit"}, "then": 0, "else": 1},
    },
    {
        "name": "echo",
        "learner": "gtd",
        "policy": "uniform",
        "cumulant": {"mul": [{"prediction": "steps"}, 0.01]},
        "continuation": 0.5,
    },
    {
        "name": "lamp",
        "learner": "gtd",
        "policy": "uniform",
        "features": {"kind": "constant"},
        "outcome": {"sensor": "color:lamp"},
        "continuation": {"if": {"sensor": "in:lamp"}, "then": 0, "else": 1},
        "reset": "episode",
        "alpha": 0.5,
        "lambda": 0.5,
    },
    {
        "name": "by_colour",
        "policy": "greedy",
        "features": {
            "kind": "stripes",
            "parts": 5,
            "condition": {"demon": "lamp", "thresholds": [-0.05, 0.05]},
        },
        "cumulant": {"sensor": "reward"},
    },
    {
        "name": "follow",
        "policy": {"of": "greedy_ctl"},
        "cumulant": {"mul": [{"max": [{"sensor": "x"}, {"sensor": "y"}]}, 0.002]},
        "discount": 0.9,
    },
    {
        "name": "follow_td",
        "learner": "td",
        "policy": {"of": "eps_ctl"},
        "cumulant": {"min": [{"sensor": "reward"}, 0]},
        "lambda": 0.3,
        "discount": 0.9,
    },
    {
        "name": "gated",
        "learner": "gtd",
        "policy": {"kind": "fixed", "probabilities": [0.1, 0.4, 0.4, 0.1]},
        "cumulant": {"if": {"prediction": "lamp"}, "then": {"prediction": "goal_prob"}, "else": 0.1},
        "continuation": {"max": [0.5, {"mul": [0.9, {"sensor": "in:crit"}]}]},
    },
]


def run_spec(behaviour: Any, **world: Any) -> RunSpec:
    fields: dict[str, Any] = {
        "width": 500,
        "height": 500,
        "step": 100,
        "slip": 0.1,
        "start": [0, 0],
        "max_steps": 40,
        "regions": [
            {"name": "goal", "kind": "terminal", "rect": [400, 400, 500, 500], "reward": 1},
            {
                "name": "pit",
                "kind": "terminal",
                "rect": [400, 200, 500, 300],
                "reward": {"indicator": "lamp", "values": {"yellow": -1, "purple": 0.5}},
            },
            {"name": "wall", "kind": "obstacle", "rect": [100, 200, 200, 300]},
            {"name": "crit", "kind": "zone", "rect": [100, 300, 400, 500]},
            {
                "name": "lamp",
                "kind": "indicator",
                "rect": [300, 100, 400, 300],
                "colors": [
                    {"name": "yellow", "value": 1, "probability": 0.5},
                    {"name": "purple", "value": -1, "probability": 0.5},
                ],
            },
        ],
    }
    fields.update(world)
    return RunSpec.model_validate(
        {
            "world": fields,
            "features": {"kind": "stripes", "parts": 5},
            "learning": {"lambda": 0.9, "alpha": 0.1, "alpha_w": 0.01},
            "behaviour": behaviour,
            "demons": DEMONS,
            "seed": 5,
        }
    )


class Recorder:
    """Wraps a Simulation's Horde so that every transition it learns from is also kept for the reference."""

    def __init__(self, sim: Simulation) -> None:
        self.events: list[tuple[Any, ...]] = []
        learn, start = sim.horde.learn, sim.horde.start_episode

        def recording_learn(state, action, b_prob, x, y, sensors, terminated, **kwargs):
            self.events.append(("learn", action, b_prob, x, y, sensors.copy(), terminated))
            return learn(state, action, b_prob, x, y, sensors, terminated, **kwargs)

        def recording_start(state, x, y):
            self.events.append(("start", x, y))
            return start(state, x, y)

        sim.horde.learn = recording_learn  # type: ignore[method-assign]
        sim.horde.start_episode = recording_start  # type: ignore[method-assign]

    def replay(self, ref: ReferenceHorde, sensor_names: list[str]) -> list[str]:
        kinds = []
        for event in self.events:
            if event[0] == "start":
                ref.observe(event[1], event[2])
            else:
                _, action, b_prob, x, y, sensors, terminated = event
                assert 0.0 < b_prob <= 1.0
                ref.learn(action, b_prob, x, y, dict(zip(sensor_names, sensors.tolist(), strict=True)), terminated)
            kinds.append(event[0])
        self.events.clear()
        return kinds


def engine_arrays(sim: Simulation) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Each demon's (theta, w, e) rows of its group's stacked arrays."""
    out = {}
    for group, learner in zip(sim.horde.groups, sim.horde_state.learners, strict=True):
        for row, i in enumerate(group.demons):
            out[sim.horde.names[i]] = (learner.theta[row], learner.w[row], learner.e[row])
    return out


def compare(sim: Simulation, ref: ReferenceHorde, step: int) -> None:
    """Every demon's theta, w, e, prediction and target policy, engine against reference."""
    arrays = engine_arrays(sim)
    hs = sim.horde_state
    for i, name in enumerate(sim.horde.names):
        demon = ref.demons[name]
        theta, w, e = arrays[name]
        ours = np.concatenate([sim.horde.weights(hs, name), theta, w, e, hs.prediction[i : i + 1], hs.pi[i]])
        plain = np.concatenate([demon.theta, demon.theta, demon.w, demon.e, [demon.prediction], demon.pi_t])
        # one cheap check per demon; the detailed assertions only run to explain a failure
        if not np.abs(ours - plain).max() <= TOLERANCE:
            where = f"demon {name!r} at step {step}"
            np.testing.assert_allclose(theta, demon.theta, rtol=0, atol=TOLERANCE, err_msg=f"theta of {where}")
            np.testing.assert_allclose(w, demon.w, rtol=0, atol=TOLERANCE, err_msg=f"w of {where}")
            np.testing.assert_allclose(e, demon.e, rtol=0, atol=TOLERANCE, err_msg=f"e of {where}")
            np.testing.assert_allclose(hs.pi[i], demon.pi_t, rtol=0, atol=TOLERANCE, err_msg=f"pi of {where}")
            raise AssertionError(f"prediction of {where}: {hs.prediction[i]} != {demon.prediction}")


BEHAVIOURS = {
    "uniform behaviour on the lattice": ("uniform", {}),
    "epsilon-greedy behaviour over base, noise and a start rectangle": (
        {"kind": "epsilon_greedy", "demon": "base", "epsilon": 0.5},
        {"noise": 15.0, "start": [0, 0, 300, 200]},
    ),
}


@pytest.mark.slow
@pytest.mark.parametrize("case", list(BEHAVIOURS))
def test_engine_equals_reference_at_every_step(case, engine, make_simulation):
    """Every engine of the simulation; the fast one runs in lockstep with a recorded numpy simulation."""
    behaviour, world = BEHAVIOURS[case]
    spec = run_spec(behaviour, **world)
    driver = new_simulation(spec, NUMPY_ENGINE)  # its transitions, recorded, feed the reference
    sim = driver if engine == NUMPY_ENGINE else make_simulation(spec)  # the engine under test
    ref = ReferenceHorde(spec)
    names = driver.world.sensor_names
    ref.observe(*driver.position)
    assert sim.position == driver.position
    compare(sim, ref, 0)
    recorder = Recorder(driver)
    terminated = truncated = 0
    blocks: set[int] = set()
    largest = dict.fromkeys(sim.horde.names, 0.0)
    conditioned = next(g for g, group in enumerate(sim.horde.groups) if group.condition >= 0)
    base_n = sim.horde.groups[conditioned].coder.base_n
    for step in range(1, 1001):
        result = driver.step()
        if sim is not driver:
            assert sim.step() == result, f"step {step}: the engines took different transitions"
            assert sim.position == driver.position, f"step {step}"
        terminated += result.terminated
        truncated += result.truncated
        kinds = recorder.replay(ref, names)
        assert kinds == (["learn", "start"] if result.done else ["learn"])
        compare(sim, ref, step)
        blocks.add(int(sim.horde_state.features[conditioned][0] // base_n))
        for name in largest:
            largest[name] = max(largest[name], float(np.abs(sim.horde.weights(sim.horde_state, name)).max()))
    # the run covered what it is meant to cover
    assert terminated >= 8 and truncated >= 8, (terminated, truncated)  # many episodes, both endings
    assert blocks == {0, 1, 2}, blocks  # the conditioned group used every block
    assert not sim.horde_state.diverged.any()
    assert min(largest.values()) > 1e-3, largest  # every demon learned something
