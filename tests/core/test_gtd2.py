"""GTD2(lambda) and the original GTD (`learners/gtd2.py`): the five kinds of STYLE item 8, for each.

1. a case computed by hand, in the oracle, the numpy form and the engine;
2. a stack of demons equal to its demons one by one (the numpy form);
3. the engine equal to the plain oracle (`reference.gtd2_step`, `gtd1_step`) on a stream mixing policies,
   continuations, a conditioned block and resets (and in the registry-wide test_real_features.py);
4. exact solutions: on Boyan's chain with its features, the oracle's expected update is zero exactly at the TD
   fixed point of `worlds/state_values.py`'s linear solve, and it is stable there; the engine gets within 5 % of
   the value range of it; off-policy on a small chain, the learner reaches the exact values;
5. dropping rho misses them.
And the original GTD's lambda = 0: a demon that sets lambda > 0 is refused naming `lambda`.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from pydantic import ValidationError

from horde.core import learners, reference
from horde.core.horde import Horde
from horde.core.learner import Learner
from horde.scenarios import find_scenario
from horde.spec import RunSpec
from horde.worlds.chains import Model, boyan_model
from horde.worlds.gym_spaces import resolve_world
from horde.worlds.state_values import demon_truth

from .test_online_learners import BEHAVIOUR_RIGHT, CHAIN, TARGET_RIGHT, exact_chain_values
from .test_tdrc import equals_the_oracle_on_a_random_stream

ORACLE = {"gtd2": reference.gtd2_step, "gtd1": reference.gtd1_step}
NUMPY = {"gtd2": learners.gtd2_update, "gtd1": learners.gtd1_update}


def one(value: float) -> np.ndarray:
    return np.full(1, value)


# ----------------------------------------------------------------------------------------------
# 1. By hand


@pytest.mark.parametrize(
    "learner, theta, w",
    [
        # GTD2: delta = 1 + 0.9 * 2 - 1 = 1.8; e = rho x_t = (2, 0); w . x_t = 0.5, w . e = 1;
        # theta' = (1, 2) + 0.1 (0.5 (1, 0) - 0.9 * 1 * (0, 1)) = (1.05, 1.91);
        # w' = (0.5, 0.4) + 0.1 (1.8 (2, 0) - 0.5 (1, 0)) = (0.81, 0.4).
        ("gtd2", [1.05, 1.91], [0.81, 0.4]),
        # GTD: u . e = 1; theta' = (1, 2) + 0.1 ((1, 0) - 0.9 (0, 1)) 1 = (1.1, 1.91);
        # u' = (0.5, 0.4) + 0.1 ((3.6, 0) - (0.5, 0.4)) = (0.81, 0.36).
        ("gtd1", [1.1, 1.91], [0.81, 0.36]),
    ],
)
def test_by_hand_in_the_oracle_and_the_numpy_form(learner: str, theta: list[float], w: list[float]) -> None:
    """Two features, theta = (1, 2), w (u) = (0.5, 0.4), alpha = alpha_w = 0.1, lambda = 0, gamma_tp1 = 0.9,
    rho = 2, r = 1, x_t = (1, 0), x_tp1 = (0, 1)."""
    x_t, x_tp1 = np.array([1.0, 0.0]), np.array([0.0, 1.0])
    t = reference.Transition(x_t, x_tp1, 1.0, 0.0, 0.0, 0.9, 2.0, 0.0)
    new_theta, new_w, e, delta = ORACLE[learner](np.array([1.0, 2.0]), np.array([0.5, 0.4]), np.zeros(2), t, 0.1, 0.1)
    assert delta == pytest.approx(1.8)
    np.testing.assert_allclose(e, [2.0, 0.0])
    np.testing.assert_allclose(new_theta, theta)
    np.testing.assert_allclose(new_w, w)
    state = learners.LearnerState(np.array([[1.0, 2.0]]), np.array([[0.5, 0.4]]), np.zeros((1, 2)))
    params = learners.LearnerParams(np.zeros(1), one(0.1), one(0.1), np.ones(1), np.ones(1))
    new, deltas = NUMPY[learner](state, params, (np.array([0]), np.array([1.0])), (np.array([1]), np.array([1.0])),
                                 one(1.0), one(0.0), one(0.0), one(0.9), one(2.0))  # fmt: skip
    assert deltas[0] == pytest.approx(1.8)
    np.testing.assert_allclose(new.theta[0], theta)
    np.testing.assert_allclose(new.w[0], w)


def stream_spec(demons: list[dict[str, Any]]) -> RunSpec:
    """Two states (sensor `state`, tabular features over it) and a `reward` sensor; actions 0 and 1."""
    return RunSpec.model_validate({
        "world": {"kind": "stream", "actions": 2, "sensors": [{"name": "state", "low": 0, "high": 1},
                                                              {"name": "reward", "low": -1, "high": 1}]},
        "features": {"kind": "table", "sensor": "state", "table": [[0], [1]]},
        "learning": {"lambda": 0.0, "alpha": 0.1, "alpha_w": 0.1},
        "demons": demons,
    })  # fmt: skip


@pytest.mark.parametrize(
    "learner, expected",
    [
        # GTD2, w from 0 (theta moves only once w is not 0: step 3):
        # 1. 0 -> 1, r 1, rho 2: delta 1.8, e (2, 0): theta (1, 2); w 0.1 * 1.8 (2, 0) = (0.36, 0).
        # 2. 1 -> 0, r 0, rho 1: delta 0.9 - 2 = -1.1, e (0, 1), w . x 0: theta (1, 2); w (0.36, -0.11).
        # 3. 0 -> 1, r 1, rho 2: delta 1.8, e (2, 0), w . x 0.36, w . e 0.72:
        #    theta (1 + 0.036, 2 - 0.1 * 0.9 * 0.72) = (1.036, 1.9352);
        #    w (0.36 + 0.1 (3.6 - 0.36), -0.11) = (0.684, -0.11).
        # 4. 1 -> 0, r 0, rho 1: delta 0.9 * 1.036 - 1.9352 = -1.0028, e (0, 1), w . x = w . e = -0.11:
        #    theta (1.036 + 0.1 * 0.9 * 0.11, 1.9352 - 0.011) = (1.0459, 1.9242);
        #    w (0.684, -0.11 + 0.1 (-1.0028 + 0.11)) = (0.684, -0.19928).
        ("gtd2", [((1.0, 2.0), (0.36, 0.0)), ((1.0, 2.0), (0.36, -0.11)), ((1.036, 1.9352), (0.684, -0.11)),
                  ((1.0459, 1.9242), (0.684, -0.19928))]),
        # GTD, u from 0, beta 0.1:
        # 1. delta 1.8, e (2, 0), u . e 0: theta (1, 2); u (0.36, 0).
        # 2. delta -1.1, e (0, 1), u . e 0: theta (1, 2); u (0.36, 0) + 0.1 (-1.1 (0, 1) - (0.36, 0)) = (0.324, -0.11).
        # 3. delta 1.8, e (2, 0), u . e 0.648: theta (1, 2) + 0.0648 ((1, 0) - 0.9 (0, 1)) = (1.0648, 1.94168);
        #    u (0.324, -0.11) + 0.1 ((3.6, 0) - (0.324, -0.11)) = (0.6516, -0.099).
        # 4. delta 0.9 * 1.0648 - 1.94168 = -0.98336, e (0, 1), u . e -0.099:
        #    theta + 0.1 (-0.099) ((0, 1) - 0.9 (1, 0)) = (1.07371, 1.93178);
        #    u (0.6516, -0.099) + 0.1 (-0.98336 (0, 1) - (0.6516, -0.099)) = (0.58644, -0.187436).
        ("gtd1", [((1.0, 2.0), (0.36, 0.0)), ((1.0, 2.0), (0.324, -0.11)), ((1.0648, 1.94168), (0.6516, -0.099)),
                  ((1.07371, 1.93178), (0.58644, -0.187436))]),
    ],
)  # fmt: skip
def test_by_hand_in_the_engine(learner: str, expected: list[Any]) -> None:
    """Four steps worked on paper: alpha = alpha_w = 0.1 over one active feature, gamma 0.9, lambda 0, target
    policy: action 1; behaviour 0.5, 1, 0.5, 1 on it (rho 2, 1, 2, 1); theta from (1, 2), w from 0."""
    spec = stream_spec([{"name": "d", "learner": learner, "policy": {"kind": "fixed", "probabilities": [0, 1]},
                         "cumulant": {"sensor": "reward"}, "discount": 0.9, "initial_weights": [1, 2]}])  # fmt: skip
    loop = Learner(Horde(spec, cut=0.0))
    loop.observe(np.array([0.0, 0.0]))
    stream = [(1, 1, 0.5), (0, 0, 1.0), (1, 1, 0.5), (0, 0, 1.0)]
    for (state, reward, b_prob), (theta, w) in zip(stream, expected, strict=True):
        loop.learn(np.array([float(state), float(reward)]), [1], [b_prob])
        ours_theta, ours_w, _ = loop.horde.demon_arrays(loop.horde_state(), "d")
        np.testing.assert_allclose(ours_theta, theta, rtol=1e-12)
        np.testing.assert_allclose(ours_w, w, rtol=1e-12, atol=1e-15)


def test_the_original_gtd_takes_lambda_0_only() -> None:
    """A demon's lambda > 0 is refused naming the field; left out, it is 0 whatever [learning] says."""
    with pytest.raises(ValidationError) as error:
        stream_spec([{"name": "d", "learner": "gtd1", "lambda": 0.5}])
    assert error.value.errors()[0]["loc"] == ("demons", 0, "lambda")
    assert "lambda = 0 only" in str(error.value)
    data = stream_spec([{"name": "d", "learner": "gtd1"}, {"name": "e", "learner": "gtd2"}]).model_dump(by_alias=True)
    spec = RunSpec.model_validate({**data, "learning": {**data["learning"], "lambda": 0.9}})
    horde = Horde(spec, cut=0.0)
    assert [d.lam for d in horde.plan.demons] == [0.0, 0.9]
    assert reference.ReferenceHorde(spec).demons["d"].lam == 0.0
    with pytest.raises(ValueError, match="lambda = 0 only"):
        learners.gtd1_update(learners.zeros(1, 2), learners.LearnerParams(one(0.5), one(0.1), one(0.1), one(1), one(1)),
                             (np.array([0]), np.ones(1)), (np.array([1]), np.ones(1)), one(0), one(0), one(1), one(1),
                             one(1))  # fmt: skip


# ----------------------------------------------------------------------------------------------
# 2. A stack equals its demons one by one


@pytest.mark.parametrize("learner", ["gtd2", "gtd1"])
def test_stack_equals_the_oracle_demon_by_demon(learner: str) -> None:
    rng = np.random.default_rng(11)
    demons, n, steps = 4, 6, 300
    lam = np.array([0.0, 0.5, 0.9, 1.0]) if learner == "gtd2" else np.zeros(demons)
    alpha, alpha_w = np.array([0.05, 0.02, 0.1, 0.01]), np.array([0.05, 0.01, 0.2, 0.02])
    params = learners.LearnerParams(lam, alpha, alpha_w, np.ones(demons), np.ones(demons))
    state = learners.zeros(demons, n)
    oracle = [(np.zeros(n), np.zeros(n), np.zeros(n)) for _ in range(demons)]
    every = np.arange(n)
    x_t, g_t = rng.normal(size=n), np.zeros(demons)  # real-valued features
    for _ in range(steps):
        x_tp1 = rng.normal(size=n) * (rng.random(n) < 0.6)
        r, g_tp1 = rng.normal(size=demons), rng.choice([0.0, 0.8, 1.0], size=demons)
        rho = rng.choice([0.0, 0.5, 2.0], size=demons)
        state, delta = NUMPY[learner](state, params, (every, x_t), (every, x_tp1), r, np.zeros(demons), g_t, g_tp1,
                                      rho)  # fmt: skip
        for d in range(demons):
            t = reference.Transition(x_t, x_tp1, r[d], 0.0, g_t[d], g_tp1[d], rho[d], lam[d])
            theta, w, e, delta_d = ORACLE[learner](*oracle[d], t, alpha[d], alpha_w[d])
            oracle[d] = (theta, w, e)
            assert delta_d == pytest.approx(delta[d], abs=1e-9)
        x_t, g_t = x_tp1, g_tp1
    for d in range(demons):
        np.testing.assert_allclose(state.theta[d], oracle[d][0], atol=1e-9)
        np.testing.assert_allclose(state.w[d], oracle[d][1], atol=1e-9)
    assert np.abs(state.w).max() > 1e-3 and np.abs(state.theta).max() > 1e-3, "both learned something"


# ----------------------------------------------------------------------------------------------
# 3. The engine equals the oracle


def test_the_engine_equals_the_oracle_on_a_random_stream() -> None:
    """GTD2 demons of several lambdas and original GTD demons (lambda 0), given policies and their own trace
    classes, a demon reset at every episode start and one over features conditioned on another's prediction,
    600 steps with episode ends, cut 0; weights, w, traces and predictions to 1e-9 at every step."""
    fixed = [[0.2, 0.8], [0.2, 0.8], [0.7, 0.3], [0.7, 0.3]]
    demons: list[dict[str, Any]] = [
        {"name": f"{learner}_{i}", "learner": learner, "policy": {"kind": "fixed", "probabilities": p},
         "lambda": lam, "cumulant": {"sensor": "reward"}, "continuation": 0.9, "alpha_w": aw}
        for learner, lams in (("gtd2", (0.0, 0.6, 0.6, 0.9)), ("gtd1", (0.0, 0.0, 0.0, 0.0)))
        for i, (p, lam, aw) in enumerate(zip(fixed, lams, (0.1, 0.05, 0.2, 0.5), strict=True))
    ]  # fmt: skip
    demons += [
        {"name": f"forgets_{learner}", "learner": learner, "policy": "uniform", "cumulant": 1.0, "reset": "episode"}
        for learner in ("gtd2", "gtd1")
    ]
    demons += [
        {"name": f"gated_{learner}", "learner": learner, "policy": {"kind": "fixed", "probabilities": [0.2, 0.8]},
         "cumulant": {"sensor": "reward"}, "continuation": {"if": {"sensor": "state"}, "then": 0.5, "else": 1},
         "features": {"kind": "table", "sensor": "state", "table": [[0], [1]],
                      "condition": {"demon": f"{learner}_0", "thresholds": [0.0]}}}
        for learner in ("gtd2", "gtd1")
    ]  # fmt: skip
    spec = stream_spec(demons)
    loop, largest = equals_the_oracle_on_a_random_stream(spec)
    for name in ("gtd2_1", "gtd1_3"):
        theta, w, _ = loop.horde.demon_arrays(loop.horde_state(), name)
        assert np.abs(w).max() > 1e-3 and np.abs(theta).max() > 1e-3, f"{name} learned something"
    assert largest > 0.0


# ----------------------------------------------------------------------------------------------
# 4. Exact solutions; 5. dropping rho misses them


def boyan_spec(learner: str, alpha: float, alpha_w: float) -> RunSpec:
    """scenarios/boyan-chain.toml with one demon of `learner`."""
    data = find_scenario("boyan-chain").model_dump(by_alias=True, exclude_none=True)
    demon = {"name": "v", "learner": learner, "policy": "uniform", "cumulant": {"sensor": "reward"}, "discount": 1.0}
    learning = {"lambda": 0.0, "alpha": alpha, "alpha_w": alpha_w}
    return resolve_world(RunSpec.model_validate({**data, "demons": [demon], "learning": learning}))


def expected_update(learner: str, z: np.ndarray, truth: Any, chain: Model) -> np.ndarray:
    """The oracle's update of z = (theta, w) summed over the chain's transitions k, each weighted by
    d(src k) p_k (one action, on-policy: rho 1)."""
    n = truth.features.shape[1]
    theta, w = np.split(z, 2)
    total = np.zeros(2 * n)
    for src, p, dst, r in zip(chain.src, chain.prob, chain.dst, chain.reward, strict=True):
        ends = dst < 0
        x_tp1 = np.zeros(n) if ends else truth.features[dst]
        t = reference.Transition(truth.features[src], x_tp1, r, 0.0, 0.0, 0.0 if ends else 1.0, 1.0, 0.0)
        new_theta, new_w, _, _ = ORACLE[learner](theta, w, np.zeros(n), t, 0.1, 0.1)
        total += truth.distribution[src] * p * np.r_[new_theta - theta, new_w - w]
    return total


@pytest.mark.parametrize("learner", ["gtd2", "gtd1"])
def test_the_expected_update_is_zero_at_the_td_fixed_point_and_stable(learner: str) -> None:
    """Boyan's chain, its four features: the oracle's expected update is affine in z = (theta, w); probed at 0 and
    the unit vectors it gives G z + g, whose zero, solved exactly, is theta = the TD fixed point of
    `state_values` (its linear solve A w = b) with w = 0; every eigenvalue of G has a negative real part, so the
    expected update goes there from anywhere (small steps)."""
    horde = Horde(boyan_spec(learner, 0.1, 0.1), cut=0.0)
    truth, chain = demon_truth(horde, "v"), boyan_model()
    assert truth is not None
    n = truth.features.shape[1]
    g = expected_update(learner, np.zeros(2 * n), truth, chain)
    G = np.column_stack([expected_update(learner, unit, truth, chain) - g for unit in np.eye(2 * n)])
    theta, w = np.split(np.linalg.solve(G, -g), 2)
    np.testing.assert_allclose(truth.features @ theta, truth.fixed_point, atol=1e-9)
    np.testing.assert_allclose(truth.fixed_point, truth.exact, atol=1e-9)  # Boyan's features: the truth
    np.testing.assert_allclose(w, 0.0, atol=1e-9)
    assert np.linalg.eigvals(G).real.max() < 0.0


@pytest.mark.slow
@pytest.mark.parametrize("learner, alpha, alpha_w, episodes", [("gtd2", 0.2, 0.4, 1500), ("gtd1", 0.2, 0.1, 3000)])
def test_the_engine_reaches_the_td_fixed_point_of_boyans_chain(learner: str, alpha: float, alpha_w: float,
                                                               episodes: int) -> None:  # fmt: skip
    """The engine on Boyan's chain (the scenario's world and features): after the episodes every state's value is
    within 5 % of the value range (24) of the TD fixed point (here the truth, -2 s)."""
    from horde.worlds.gymnasium import GymAgent

    spec = boyan_spec(learner, alpha, alpha_w)
    agent = GymAgent(spec, np.random.default_rng(3))
    for _ in range(episodes):
        agent.run_episode()
    truth = demon_truth(agent.learner.horde, "v")
    assert truth is not None
    theta = agent.learner.horde.weights(agent.learner.horde_state(), "v")
    assert np.abs(truth.features @ theta - truth.fixed_point).max() <= 0.05 * 24


def run_chain(learner: str, steps: int, rho_scale: float = 1.0, seed: int = 0) -> np.ndarray:
    """One demon (the numpy form) on the chain of test_online_learners (tabular), behaviour 50/50, target 80/20
    (GTD2: lambda 0.5, alpha 0.05, alpha_w 0.1; GTD: alpha = beta = 0.1); theta averaged over the second half of
    the steps (at these constant step sizes the original GTD's theta wanders about 0.05 around its answer)."""
    rng = np.random.default_rng(seed)
    lam, alpha = (0.5, 0.05) if learner == "gtd2" else (0.0, 0.1)
    params = learners.LearnerParams(one(lam), one(alpha), one(0.1), np.ones(1), np.ones(1))
    state = learners.zeros(1, CHAIN)
    s, g_t = 2, 0.0
    average = np.zeros(CHAIN)
    for step in range(steps):
        right = rng.random() < BEHAVIOUR_RIGHT
        rho = (TARGET_RIGHT / BEHAVIOUR_RIGHT if right else (1 - TARGET_RIGHT) / (1 - BEHAVIOUR_RIGHT)) ** rho_scale
        s_next = s + (1 if right else -1)
        done = s_next < 0 or s_next >= CHAIN
        x_tp1 = (np.zeros(0, np.int64), np.zeros(0)) if done else (np.array([s_next]), np.ones(1))
        z = 1.0 if s_next >= CHAIN else 0.0
        g_tp1 = 0.0 if done else 1.0
        state, _ = NUMPY[learner](state, params, (np.array([s]), np.ones(1)), x_tp1, one(0.0), one(z), one(g_t),
                                  one(g_tp1), one(rho))  # fmt: skip
        s, g_t = (2, 0.0) if done else (s_next, g_tp1)
        if step >= steps // 2:
            average += state.theta[0] / (steps - steps // 2)
    return average


@pytest.mark.slow
@pytest.mark.parametrize("learner", ["gtd2", "gtd1"])
def test_converges_off_policy_and_misses_without_rho(learner: str) -> None:
    exact = exact_chain_values(TARGET_RIGHT)
    theta = np.mean([run_chain(learner, 40_000, seed=seed) for seed in (0, 1)], axis=0)
    np.testing.assert_allclose(theta, exact, atol=0.05)
    without = run_chain(learner, 40_000, rho_scale=0.0)
    assert abs(without[2] - exact[2]) > 0.1
