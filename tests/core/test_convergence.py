"""Convergence to the exact solution of a small problem (DESIGN section 7; RLPark's GQTest).

A 5 x 5 lattice world with one tabular feature per cell, a goal and a pit, a uniform behaviour and a
fixed non-uniform target policy. Two GQ(0) demons follow the target policy off-policy: one predicts the
number of steps to termination (cumulant 1), one the probability of ending in the goal (outcome in:goal).

Why GQ(0) with alpha_w = 0: on a deterministic world the expected-Sarsa target r + sum_a' pi(a') q(s', a')
of an action value is deterministic given (s, a), so the tabular iterates converge to the exact values
without sampling noise and a constant step size reaches 3 % quickly. (A GTD(0) state-value demon sees
the target policy's randomness through rho and needs ~10^5 steps for 3 % in every state: that case is
tested with a looser bound in test_importance_ratio.py. A positive alpha_w leaves the fixed point alone
but makes the early iterates follow the slow gradient of the Bellman error; see test_baird.py for w.)
"""

from __future__ import annotations

import numpy as np
import pytest

from horde.core import evaluate
from horde.core.simulation import Simulation
from horde.spec import RunSpec

TARGET = [0.4, 0.1, 0.1, 0.4]  # up, down, left, right


def lattice_spec(seed: int = 3, extra_regions: tuple[dict[str, object], ...] = (), **world: object) -> RunSpec:
    return RunSpec.model_validate(
        {
            "world": {
                "width": 500,
                "height": 500,
                "step": 100,
                "noise": 0,
                "start": [0, 0],
                "max_steps": 50,  # truncated episodes bootstrap: the answer must not notice them
                "regions": [
                    {"name": "goal", "kind": "terminal", "rect": [400, 400, 500, 500], "reward": 1},
                    {"name": "pit", "kind": "terminal", "rect": [400, 0, 500, 100], "reward": -1},
                    {"name": "mud", "kind": "zone", "rect": [0, 200, 300, 300]},
                    *extra_regions,
                ],
                **world,
            },
            "features": {"kind": "grid", "tiles": 5},
            "behaviour": "uniform",
            "learning": {"lambda": 0.0, "alpha": 0.5, "alpha_w": 0.0},
            "demons": [
                {"name": "steps", "policy": {"kind": "fixed", "probabilities": TARGET}, "cumulant": 1},
                {
                    "name": "to_goal",
                    "policy": {"kind": "fixed", "probabilities": TARGET},
                    "outcome": {"sensor": "in:goal"},
                },
                {
                    "name": "discounted",
                    "policy": {"kind": "fixed", "probabilities": [0.1, 0.2, 0.3, 0.4]},
                    "cumulant": {"sensor": "reward"},
                    "outcome": {"sensor": "bump"},
                    "continuation": {"if": {"sensor": "in:mud"}, "then": 0.5, "else": 1},
                    "discount": 0.9,
                },
            ],
            "seed": seed,
        }
    )


WALL = {"name": "wall", "kind": "obstacle", "rect": [200, 100, 300, 200]}


@pytest.mark.parametrize(
    ("world", "cells"),
    [({}, 23), ({"slip": 0.2, "extra_regions": (WALL,), "transient_reward": -0.1}, 22)],
    ids=["deterministic", "slip, a wall, a zone, discount"],
)
def test_exact_agrees_with_monte_carlo(world, cells):
    sim = Simulation(lattice_spec(**world))
    rng = np.random.default_rng(0)
    for name in ("steps", "to_goal", "discounted"):
        lattice = evaluate.exact(sim.horde, sim.horde_state, name)
        assert len(lattice.x) == cells  # 25 cells minus the terminals (and the wall)
        for point in [(0.0, 0.0), (300.0, 0.0), (400.0, 300.0), (100.0, 200.0)]:
            i = int(np.flatnonzero((lattice.x == point[0]) & (lattice.y == point[1]))[0])
            truth = evaluate.monte_carlo(sim.horde, sim.horde_state, name, point, 4000, 10_000, rng)
            assert truth.capped == 0
            error = abs(truth.mean - lattice.value[i])
            assert error < 4 * truth.stderr + 1e-9, (name, point, truth, lattice.value[i])


def test_exact_values_by_hand_next_to_the_goal():
    """Below the goal, (400, 300): up ends in the goal; right bumps and stays; left and down move away."""
    sim = Simulation(lattice_spec())
    lattice = evaluate.exact(sim.horde, sim.horde_state, "to_goal")
    v = dict(zip(zip(lattice.x.tolist(), lattice.y.tolist(), strict=True), lattice.value.tolist(), strict=True))
    # v(400,300) = 0.4 * 1 + 0.4 * v(400,300) + 0.1 * v(300,300) + 0.1 * v(400,200)
    expected = (0.4 + 0.1 * v[(300.0, 300.0)] + 0.1 * v[(400.0, 200.0)]) / (1 - 0.4)
    assert abs(v[(400.0, 300.0)] - expected) < 1e-12


@pytest.mark.slow
def test_off_policy_gq_converges_to_the_exact_answer():
    sim = Simulation(lattice_spec())
    for _ in range(20_000):
        sim.step()
    assert sim.episode > 300
    for name in ("steps", "to_goal", "discounted"):
        lattice = evaluate.exact(sim.horde, sim.horde_state, name)
        predicted = sim.horde.forward(sim.horde_state, lattice.x, lattice.y).prediction[:, sim.horde.index[name]]
        # within 3 % of the exact answer in every state ("discounted" crosses 0: within 0.01 there)
        tolerance = np.full(len(lattice.value), 0.01) if name == "discounted" else 0.03 * np.abs(lattice.value)
        error = np.abs(predicted - lattice.value)
        worst = int(np.argmax(error / tolerance))
        assert (error < tolerance).all(), (name, lattice.x[worst], lattice.y[worst], lattice.value[worst], error[worst])
