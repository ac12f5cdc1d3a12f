"""The importance ratio rho = pi(a_t | s_t) / b(a_t | s_t) (DESIGN section 5, known pitfalls).

Each test here fails under one of the pitfalls: rho never reaching the update, rho applied twice, the
trace decayed with gamma_tp1 instead of gamma_t, and a sign error in the gradient-correction term.
"""

from __future__ import annotations

import numpy as np
import pytest

from grids import GOAL, PIT, grid
from horde.core import evaluate, learners
from horde.core.horde import Horde
from horde.core.simulation import Simulation
from horde.spec import RunSpec

# One step from a state whose trace is not zero, with rho != 1 and gamma_t != gamma_tp1:
# theta = [1, 0, 0.5], w = [0.2, 0, 0], e_{t-1} = [0, 1, 0], phi_t = [1, 0, 1],
# r = 0.5, z = 2, gamma_t = 0.5, gamma_tp1 = 0.8, rho = 2, lambda = 0.9, alpha = 0.1, alpha_w = 0.05.
THETA, W, E_PREV = [1.0, 0.0, 0.5], [0.2, 0.0, 0.0], [0.0, 1.0, 0.0]
X_T = (np.array([0, 2]), np.array([1.0, 1.0]))


def single_step(kind: str, x_bar: tuple[np.ndarray, np.ndarray]) -> tuple[learners.LearnerState, float]:
    rho_in_trace, correct = {"gq": (0.0, 1.0), "gtd": (1.0, 1.0), "td": (1.0, 0.0)}[kind]
    p = learners.LearnerParams(
        np.array([0.9]), np.array([0.1]), np.array([0.05]), np.array([rho_in_trace]), np.array([correct])
    )
    state = learners.LearnerState(np.array([THETA]), np.array([W]), np.array([E_PREV]))
    new, delta = learners.update(
        state,
        p,
        X_T,
        x_bar,
        np.array([0.5]),
        np.array([2.0]),
        np.array([0.5]),
        np.array([0.8]),
        np.array([2.0]),
    )
    return new, float(delta[0])


def test_gq_single_step_by_hand():
    """phi_bar = [0, 0.5, 0.25].

    delta = 0.5 + 0.2 * 2 + 0.8 * (0.5 * 0.25) - (1 + 0.5)                  = -0.5
    e     = phi_t + gamma_t lambda rho e_prev = [1,0,1] + 0.5*0.9*2*[0,1,0]   = [1, 0.9, 1]
    w.e   = 0.2
    theta = theta + 0.1 * (-0.5 * e - 0.8 * 0.1 * 0.2 * [0, 0.5, 0.25])       = [0.95, -0.0458, 0.4496]
    w     = w + 0.05 * (-0.5 * e - (w.phi_t = 0.2) * phi_t)                    = [0.165, -0.0225, -0.035]

    The pitfalls give: rho dropped e = [1, 0.45, 1]; rho twice e = [2, 1.8, 2]; gamma_tp1 in the
    decay e = [1, 1.44, 1]; the correction's sign flipped theta = [0.95, -0.0442, 0.4504].
    """
    new, delta = single_step("gq", (np.array([1, 2]), np.array([[0.5, 0.25]])))
    assert delta == pytest.approx(-0.5, abs=1e-15)
    np.testing.assert_allclose(new.e[0], [1.0, 0.9, 1.0], atol=1e-15)
    np.testing.assert_allclose(new.theta[0], [0.95, -0.0458, 0.4496], atol=1e-15)
    np.testing.assert_allclose(new.w[0], [0.165, -0.0225, -0.035], atol=1e-15)


def test_gtd_single_step_by_hand():
    """phi_tp1 = [0, 1, 1].

    delta = 0.5 + 0.2 * 2 + 0.8 * (0 + 0.5) - (1 + 0.5)                      = -0.2
    e     = rho (phi_t + gamma_t lambda e_prev) = 2 * ([1,0,1] + 0.45 [0,1,0])  = [2, 0.9, 2]
    w.e   = 0.4
    theta = theta + 0.1 * (-0.2 * e - 0.8 * 0.1 * 0.4 * [0, 1, 1])            = [0.96, -0.0212, 0.4568]
    w     = w + 0.05 * (-0.2 * e - 0.2 * phi_t)                               = [0.17, -0.009, -0.03]

    The pitfalls give: rho dropped e = [1, 0.45, 1]; rho twice e = [2, 1.8, 2]; gamma_tp1 in the
    decay e = [2, 1.44, 2]; the correction's sign flipped theta = [0.96, -0.0148, 0.4632].
    """
    new, delta = single_step("gtd", (np.array([1, 2]), np.array([1.0, 1.0])))
    assert delta == pytest.approx(-0.2, abs=1e-15)
    np.testing.assert_allclose(new.e[0], [2.0, 0.9, 2.0], atol=1e-15)
    np.testing.assert_allclose(new.theta[0], [0.96, -0.0212, 0.4568], atol=1e-15)
    np.testing.assert_allclose(new.w[0], [0.17, -0.009, -0.03], atol=1e-15)


def test_td_single_step_by_hand():
    """TD: the GTD trace, no correction, no w.

    theta = theta + 0.1 * -0.2 * [2, 0.9, 2] = [0.96, -0.018, 0.46]
    """
    new, delta = single_step("td", (np.array([1, 2]), np.array([1.0, 1.0])))
    assert delta == pytest.approx(-0.2, abs=1e-15)
    np.testing.assert_allclose(new.theta[0], [0.96, -0.018, 0.46], atol=1e-15)
    np.testing.assert_allclose(new.w[0], W, atol=0)


def constant_spec(learner: str) -> RunSpec:
    return RunSpec.model_validate(
        {
            "world": {"width": 500, "height": 500, "step": 100, "start": [200, 200]},
            "features": {"kind": "constant"},
            "learning": {"lambda": 0.5, "alpha": 0.1, "alpha_w": 0.0},
            "behaviour": {"kind": "fixed", "probabilities": [0.5, 0.2, 0.2, 0.1]},
            "demons": [
                {
                    "name": "d",
                    "learner": learner,
                    "policy": {"kind": "fixed", "probabilities": [0.7, 0.1, 0.1, 0.1]},
                    "cumulant": 1,
                }
            ],
            "seed": 29,  # its first two actions are up (b = 0.5), then down (b = 0.2)
        }
    )


def two_steps(learner: str) -> tuple[Horde, list[float]]:
    """Two steps of the simulation: a_0 = up with b = 0.5, a_1 = down with b = 0.2."""
    sim = Simulation(constant_spec(learner), cut=0.0)
    out = []
    for action, b_prob in ((0, 0.5), (1, 0.2)):
        assert sim.step().action == action and sim.behaviour_probability == b_prob
        out.append(sim.horde.weights(sim.horde_state, "d").tolist())
    return sim.horde, out


def test_the_horde_passes_pi_over_b_to_gtd():
    """One constant feature; rho_0 = 0.7 / 0.5 = 1.4, rho_1 = 0.1 / 0.2 = 0.5; alpha 0.1, lambda 0.5.

    step 0: delta = 1, e = 1.4 * 1 = 1.4, theta = 0.1 * 1 * 1.4 = 0.14
    step 1: delta = 1 + 0.14 - 0.14 = 1, e = 0.5 * (1 + 1 * 0.5 * 1.4) = 0.85, theta = 0.14 + 0.085 = 0.225
    """
    _, weights = two_steps("gtd")
    np.testing.assert_allclose(weights, [[0.14], [0.225]], atol=1e-15)


def test_the_horde_passes_pi_over_b_to_gq():
    """phi(s, a) is one-hot on a; rho_0 = 1.4, rho_1 = 0.5.

    step 0: delta = 1, e = [1,0,0,0], theta = [0.1, 0, 0, 0]
    step 1: delta = 1 + (0.7 * 0.1) - 0 = 1.07, e = [0,1,0,0] + 1 * 0.5 * 0.5 * [1,0,0,0] = [0.25, 1, 0, 0]
            theta = [0.1, 0, 0, 0] + 0.1 * 1.07 * e = [0.12675, 0.107, 0, 0]
    """
    _, weights = two_steps("gq")
    np.testing.assert_allclose(weights, [[0.1, 0, 0, 0], [0.12675, 0.107, 0, 0]], atol=1e-15)


TARGET = [0.4, 0.1, 0.1, 0.4]


def lattice_spec(policy: object) -> RunSpec:
    return RunSpec.model_validate(
        {
            "world": grid(GOAL, PIT | {"rect": [400, 0, 500, 100]}),
            "features": {"kind": "grid", "tiles": 5},
            "behaviour": "uniform",
            "learning": {"lambda": 0.5, "alpha": 0.1, "alpha_w": 0.0},
            "demons": [
                {"name": "steps", "learner": "gtd", "policy": policy, "cumulant": 1},
                {"name": "to_goal", "learner": "gtd", "policy": policy, "outcome": {"sensor": "in:goal"}},
            ],
            "seed": 2,
        }
    )


def relative_error(predicted: np.ndarray, truth: np.ndarray) -> float:
    """Mean absolute error over the lattice, relative to the mean absolute truth."""
    return float(np.mean(np.abs(predicted - truth)) / np.mean(np.abs(truth)))


def test_off_policy_gtd_learns_the_target_policys_answer_not_the_behaviours():
    """Uniform behaviour, target (0.4, 0.1, 0.1, 0.4): ~15 steps to termination from the start, ~53 under b.

    Measured over five seeds after 10,000 steps (relative_error, steps / to_goal): correct 6-13 % / 1-3 %;
    without rho ~230 % / ~55 % (it heads for the behaviour's answer); with rho applied twice 37-45 % / 5-8 %.
    State values are used because with tabular features the action values of GQ reach Q^pi whatever the
    trace does with rho: E[delta | s, a] = 0 there for every action.
    """
    sim = Simulation(lattice_spec({"kind": "fixed", "probabilities": TARGET}))
    for _ in range(10_000):
        sim.step()
    behaviour = Simulation(lattice_spec("uniform"))
    for name, bound in {"steps": 0.2, "to_goal": 0.1}.items():
        target = evaluate.exact(sim.horde, sim.horde_state, name)
        under_b = evaluate.exact(behaviour.horde, behaviour.horde_state, name)
        assert relative_error(under_b.value, target.value) > 0.3  # the two answers are far apart
        predicted = sim.horde.forward(sim.horde_state, target.x, target.y).prediction[:, sim.horde.index[name]]
        error, error_b = relative_error(predicted, target.value), relative_error(predicted, under_b.value)
        assert error < bound, (name, error, error_b)
        assert error_b > 3 * error, (name, error, error_b)
