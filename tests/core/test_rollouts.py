"""The compiled Monte-Carlo rollouts (`evaluate.monte_carlo`, `core/rollouts.py`) against exact answers.

On a lattice world `evaluate.exact` solves each question's linear system; the rollouts' mean must lie
within four standard errors of it for questions that read other demons' predictions, follow another
demon's policy or their own action values, and use conditioned features or features tiled over sensors.
Indicator colours, noise and the cap are checked against answers computed by hand.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from grids import CRIT, GOAL, PIT, WALL, grid, lamp, lamp_terminal
from horde.core import evaluate
from horde.core.simulation import Simulation
from horde.spec import RunSpec

RIGHT = [0.0, 0.0, 0.0, 1.0]  # up, down, left, right

DEMONS: list[dict[str, Any]] = [
    {"name": "base", "policy": {"kind": "softmax", "temperature": 0.2}, "cumulant": {"sensor": "reward"},
     "alpha": 0.05, "lambda": 0.5},
    {"name": "eps_ctl", "policy": {"kind": "epsilon_greedy", "epsilon": 0.3}, "cumulant": -0.01,
     "outcome": {"sensor": "in:goal"}, "discount": 0.95, "features": {"kind": "tiles", "tilings": 4, "tiles": 4}},
    {"name": "steps", "learner": "gtd", "policy": {"of": "base"}, "cumulant": 1, "alpha": 0.05},
    {"name": "echo", "learner": "td", "policy": {"of": "eps_ctl"},
     "cumulant": {"mul": [{"prediction": "steps"}, 0.01]}, "continuation": 0.8},
    {"name": "gated", "learner": "gtd", "policy": {"kind": "fixed", "probabilities": [0.1, 0.4, 0.4, 0.1]},
     "cumulant": {"if": {"prediction": "steps"}, "then": {"sensor": "in:crit"}, "else": 0.5},
     "continuation": {"if": {"sensor": "in:crit"}, "then": 0.5, "else": 0.9},
     "features": {"kind": "stripes", "parts": 5, "condition": {"demon": "steps", "thresholds": [5.0, 20.0]}}},
    {"name": "sensed", "learner": "gtd", "policy": {"of": "base"}, "outcome": {"sensor": "in:goal"}, "alpha": 0.02,
     "features": {"kind": "sensors", "tilings": 3, "tiles": 4, "size": 24, "sensors": [
         {"sensor": "x", "low": 0, "high": 500}, {"sensor": "y", "low": 0, "high": 500},
         {"sensor": "in:crit", "low": 0, "high": 1}]}},
]  # fmt: skip


def lattice_spec() -> RunSpec:
    return RunSpec.model_validate(
        {
            "world": grid(GOAL, PIT, WALL, CRIT, slip=0.1, max_steps=40, transient_reward=-0.05),
            "features": {"kind": "stripes", "parts": 5},
            "learning": {"lambda": 0.9, "alpha": 0.1, "alpha_w": 0.001},
            "behaviour": "uniform",
            "demons": DEMONS,
            "seed": 11,
        }
    )


@pytest.fixture(scope="module")
def learned() -> Simulation:
    """A simulation whose demons have learned a while, so that the policies and predictions read are not flat."""
    sim = Simulation(lattice_spec())
    sim.run(4000)
    return sim


@pytest.mark.parametrize("name", [d["name"] for d in DEMONS])
def test_rollouts_agree_with_the_exact_answer(learned: Simulation, name: str) -> None:
    sim = learned
    state = sim.horde_state
    lattice = evaluate.exact(sim.horde, state, name)
    rng = np.random.default_rng(1)
    for point in [(0.0, 0.0), (300.0, 100.0)]:
        i = int(np.flatnonzero((lattice.x == point[0]) & (lattice.y == point[1]))[0])
        truth = evaluate.monte_carlo(sim.horde, state, name, point, 3000, 10_000, rng)
        assert truth.capped == 0 and truth.rollouts == 3000
        assert abs(truth.mean - lattice.value[i]) < 4 * truth.stderr + 1e-9, (name, point, truth, lattice.value[i])


def test_the_policy_followed_is_learned_not_uniform(learned: Simulation) -> None:
    """The test above means something only if the learned policies differ from uniform where it starts."""
    state = learned.horde_state
    assert not state.diverged.any()
    pi = learned.horde.forward(state, np.array([0.0]), np.array([0.0])).pi[0]
    for name in ("base", "eps_ctl"):
        assert np.abs(pi[learned.horde.index[name]] - 0.25).max() > 0.03, (name, pi[learned.horde.index[name]])


def test_rollouts_draw_the_indicators_colour_each_time() -> None:
    """One step right ends in a terminal paying +1 when the lamp is yellow (p 0.3), -1 when purple: -0.4."""
    world = grid(
        lamp([0, 0, 200, 100], yellow=(1.0, 0.3), purple=(-1.0, 0.7)),
        lamp_terminal("end", [100, 0, 200, 100], yellow=1.0, purple=-1.0),
        transient_reward=0.0,
    )
    spec = RunSpec.model_validate(
        {
            "world": world,
            "features": {"kind": "grid", "tiles": 5},
            "demons": [
                {
                    "name": "reward",
                    "policy": {"kind": "fixed", "probabilities": RIGHT},
                    "cumulant": {"sensor": "reward"},
                },
                {
                    "name": "colour",
                    "policy": {"kind": "fixed", "probabilities": RIGHT},
                    "continuation": 0,
                    "outcome": {"sensor": "color:lamp"},
                },
            ],
        }
    )
    sim = Simulation(spec)
    for name in ("reward", "colour"):
        truth = evaluate.monte_carlo(sim.horde, sim.horde_state, name, (0.0, 0.0), 4000, 100, np.random.default_rng(2))
        assert truth.stderr > 0.01, "the colour is drawn again for every rollout"
        assert abs(truth.mean - -0.4) < 4 * truth.stderr, (name, truth)


def test_rollouts_move_with_the_worlds_noise() -> None:
    """One noisy step right from (200, 200): x is 300 on average, spread by the noise (sd 10)."""
    spec = RunSpec.model_validate(
        {
            "world": grid(noise=10.0, start=[200, 200]),
            "features": {"kind": "grid", "tiles": 5},
            "demons": [
                {
                    "name": "x_next",
                    "policy": {"kind": "fixed", "probabilities": RIGHT},
                    "outcome": {"sensor": "x"},
                    "continuation": 0,
                },
            ],
        }
    )
    sim = Simulation(spec)
    rng = np.random.default_rng(3)
    truth = evaluate.monte_carlo(sim.horde, sim.horde_state, "x_next", (200.0, 200.0), 4000, 10, rng)
    assert abs(truth.mean - 300.0) < 4 * truth.stderr, truth
    assert truth.stderr * np.sqrt(4000) == pytest.approx(10.0, rel=0.1)


def test_rollouts_stop_at_the_cap_and_count_it() -> None:
    """Steps to termination from (0, 0) take at least 6 steps (to the pit): with a cap of 3 every rollout is
    capped and counts the 3 steps taken; so is a question whose continuation 0.8 never falls to the floor."""
    sim = Simulation(lattice_spec())
    capped = evaluate.monte_carlo(sim.horde, sim.horde_state, "steps", (0.0, 0.0), 50, 3, np.random.default_rng(4))
    assert (capped.capped, capped.mean, capped.cap) == (50, 3.0, 3)
    once = evaluate.monte_carlo(sim.horde, sim.horde_state, "echo", (0.0, 0.0), 50, 3, np.random.default_rng(4))
    assert once.capped == 50
    again = evaluate.monte_carlo(sim.horde, sim.horde_state, "echo", (0.0, 0.0), 50, 3, np.random.default_rng(4))
    assert again == once, "the same generator state gives the same rollouts"
