"""TDRC(lambda) (`learners/tdrc.py`), the learner added as one module: the five kinds of STYLE item 8.

1. a case computed by hand, in the oracle, the numpy form and the engine;
2. a stack of demons equal to its demons one by one (the numpy form), and the engine's block of several
   demons equal to each demon learning alone;
3. the engine equal to the plain oracle (`reference.tdrc_step`) on a stream mixing policies, continuations,
   a conditioned block and resets (and in the registry-wide test_real_features.py);
4. convergence off-policy to the exact answer of a small chain;
5. dropping rho misses that answer.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from horde.core import learners, reference
from horde.core.horde import Horde
from horde.core.learner import Learner
from horde.spec import RunSpec

from .test_online_learners import BEHAVIOUR_RIGHT, CHAIN, TARGET_RIGHT, exact_chain_values


def oracle_step(theta, h, e, x_t, x_tp1, r, g_t, g_tp1, rho, lam, alpha, eta, beta):  # type: ignore[no-untyped-def]
    t = reference.Transition(x_t, x_tp1, r, 0.0, g_t, g_tp1, rho, lam)
    return reference.tdrc_step(theta, h, e, t, alpha, eta * alpha, beta)


# ----------------------------------------------------------------------------------------------
# 1. By hand


def test_tdrc_by_hand_in_the_oracle_and_the_numpy_form() -> None:
    """Two features, theta = (1, 2), h = (0.5, 0), alpha = alpha_h = 0.1, beta = 1, lambda = 0, gamma_tp1 = 0.9,
    rho = 2, r = 1, x_t = (1, 0), x_tp1 = (0, 1):
    delta = 1 + 0.9 * 2 - 1 = 1.8; e = rho x_t = (2, 0); h . e = 1;
    theta' = (1, 2) + 0.1 ((3.6, 0) - 0.9 * 1 * (0, 1)) = (1.36, 1.91);
    h . x_t = 0.5; h' = (0.5, 0) + 0.1 ((3.6, 0) - 0.5 (1, 0)) - 0.1 * 1 * (0.5, 0) = (0.76, 0)."""
    x_t, x_tp1 = np.array([1.0, 0.0]), np.array([0.0, 1.0])
    theta, h, e, delta = oracle_step(np.array([1.0, 2.0]), np.array([0.5, 0.0]), np.zeros(2), x_t, x_tp1, 1.0, 0.0,
                                     0.9, 2.0, 0.0, 0.1, 1.0, 1.0)  # fmt: skip
    assert delta == pytest.approx(1.8)
    np.testing.assert_allclose(e, [2.0, 0.0])
    np.testing.assert_allclose(theta, [1.36, 1.91])
    np.testing.assert_allclose(h, [0.76, 0.0])
    # the numpy form: a stack of one
    state = learners.LearnerState(np.array([[1.0, 2.0]]), np.array([[0.5, 0.0]]), np.zeros((1, 2)))
    params = learners.LearnerParams(np.zeros(1), np.full(1, 0.1), np.full(1, 0.1), np.ones(1), np.ones(1))
    new, deltas = learners.tdrc_update(state, params, np.ones(1), (np.array([0]), np.array([1.0])),
                                       (np.array([1]), np.array([1.0])), np.ones(1), np.zeros(1), np.zeros(1),
                                       np.full(1, 0.9), np.full(1, 2.0))  # fmt: skip
    assert deltas[0] == pytest.approx(1.8)
    np.testing.assert_allclose(new.theta[0], [1.36, 1.91])
    np.testing.assert_allclose(new.w[0], [0.76, 0.0])


def stream_spec(demons: list[dict[str, Any]]) -> RunSpec:
    """Two states (sensor `state`, tabular features over it) and a `reward` sensor; actions 0 and 1."""
    return RunSpec.model_validate({
        "world": {"kind": "stream", "actions": 2, "sensors": [{"name": "state", "low": 0, "high": 1},
                                                              {"name": "reward", "low": -1, "high": 1}]},
        "features": {"kind": "table", "sensor": "state", "table": [[0], [1]]},
        "learning": {"lambda": 0.0, "alpha": 0.1},
        "demons": demons,
    })  # fmt: skip


def test_tdrc_by_hand_in_the_engine() -> None:
    """Three steps worked on paper (alpha = alpha_h = 0.1 over one active feature, beta 1, gamma 0.9,
    lambda 0, target policy: action 1; behaviour 0.5, then 1, then 0.5 on it), theta from (1, 2), h from 0:
    1. state 0 -> 1, r 1, rho 2: delta 1.8, e (2, 0), h . e 0: theta (1.36, 2); h 0.1 (3.6, 0) = (0.36, 0).
    2. state 1 -> 0, r 0, rho 1: delta 0.9 * 1.36 - 2 = -0.776, e (0, 1), h . e 0, h . x 0:
       theta (1.36, 1.9224); h = (0.36, 0) + 0.1 (0, -0.776) - 0.1 (0.36, 0) = (0.324, -0.0776).
    3. state 0 -> 1, r 1, rho 2: delta 1 + 0.9 * 1.9224 - 1.36 = 1.37016, e (2, 0), h . e 0.648, h . x 0.324:
       theta = (1.36 + 0.274032, 1.9224 - 0.1 * 0.9 * 0.648) = (1.634032, 1.86408);
       h = (0.324 + 0.1 (2.74032 - 0.324) - 0.0324, -0.0776 + 0.00776) = (0.533232, -0.06984)."""
    spec = stream_spec([{"name": "d", "learner": "tdrc", "policy": {"kind": "fixed", "probabilities": [0, 1]},
                         "cumulant": {"sensor": "reward"}, "discount": 0.9, "initial_weights": [1, 2]}])  # fmt: skip
    loop = Learner(Horde(spec, cut=0.0))
    loop.observe(np.array([0.0, 0.0]))
    expected = [((1.36, 2.0), (0.36, 0.0)), ((1.36, 1.9224), (0.324, -0.0776)),
                ((1.634032, 1.86408), (0.533232, -0.06984))]  # fmt: skip
    for (state, reward, b_prob), (theta, h) in zip([(1, 1, 0.5), (0, 0, 1.0), (1, 1, 0.5)], expected, strict=True):
        loop.learn(np.array([float(state), float(reward)]), [1], [b_prob])
        ours_theta, ours_h, _ = loop.horde.demon_arrays(loop.horde_state(), "d")
        np.testing.assert_allclose(ours_theta, theta, rtol=1e-12)
        np.testing.assert_allclose(ours_h, h, rtol=1e-12, atol=1e-15)


# ----------------------------------------------------------------------------------------------
# 2. A stack equals its demons one by one; the engine's block equals each demon alone


def test_stack_equals_the_oracle_demon_by_demon() -> None:
    rng = np.random.default_rng(11)
    demons, n, steps = 4, 6, 300
    lam = np.array([0.0, 0.5, 0.9, 1.0])
    alpha, eta, beta = np.array([0.05, 0.02, 0.1, 0.01]), np.array([1.0, 0.5, 2.0, 1.0]), np.array([1.0, 0.0, 2.5, 1.0])
    params = learners.LearnerParams(lam, alpha, eta * alpha, np.ones(demons), np.ones(demons))
    state = learners.zeros(demons, n)
    oracle = [(np.zeros(n), np.zeros(n), np.zeros(n)) for _ in range(demons)]
    every = np.arange(n)
    x_t, g_t = rng.normal(size=n), np.zeros(demons)  # real-valued features
    for _ in range(steps):
        x_tp1 = rng.normal(size=n) * (rng.random(n) < 0.6)
        r, g_tp1 = rng.normal(size=demons), rng.choice([0.0, 0.8, 1.0], size=demons)
        rho = rng.choice([0.0, 0.5, 2.0], size=demons)
        state, delta = learners.tdrc_update(state, params, beta, (every, x_t), (every, x_tp1), r, np.zeros(demons),
                                            g_t, g_tp1, rho)  # fmt: skip
        for d in range(demons):
            theta, h, e = oracle[d]
            theta, h, e, delta_d = oracle_step(theta, h, e, x_t, x_tp1, r[d], g_t[d], g_tp1[d], rho[d], lam[d],
                                               alpha[d], eta[d], beta[d])  # fmt: skip
            oracle[d] = (theta, h, e)
            assert delta_d == pytest.approx(delta[d], abs=1e-9)
        x_t, g_t = x_tp1, g_tp1
    for d in range(demons):
        np.testing.assert_allclose(state.theta[d], oracle[d][0], atol=1e-9)
        np.testing.assert_allclose(state.w[d], oracle[d][1], atol=1e-9)
    assert np.abs(state.w).max() > 1e-3, "h learned something"


DEMONS: list[dict[str, Any]] = [
    {"name": f"d{i}", "learner": "tdrc", "policy": {"kind": "fixed", "probabilities": p}, "lambda": lam,
     "cumulant": {"sensor": "reward"}, "continuation": 0.9, "parameters": {"beta": beta}}
    for i, (p, lam, beta) in enumerate([([0.2, 0.8], 0.0, 1.0), ([0.2, 0.8], 0.6, 1.0), ([0.7, 0.3], 0.6, 0.3),
                                        ([0.7, 0.3], 0.6, 4.0)])
]  # fmt: skip


def random_stream(loop: Learner, steps: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    loop.observe(np.array([0.0, 0.0]))
    for _ in range(steps):
        action = int(rng.random() < 0.5)
        state = float(rng.integers(2))
        loop.learn(np.array([state, rng.normal() * 0.3]), [action], [0.5])


def test_a_block_of_demons_equals_each_demon_alone() -> None:
    together = Learner(Horde(stream_spec(DEMONS), cut=0.0))
    blocks = together.horde.blocks
    assert len(blocks) == 2 and blocks[1].num_classes == 2  # lambda 0 alone; lambda 0.6: two target policies
    random_stream(together, 500, seed=2)
    state = together.horde_state()
    for demon in DEMONS:
        alone = Learner(Horde(stream_spec([demon]), cut=0.0))
        random_stream(alone, 500, seed=2)
        for ours, its in zip(together.horde.demon_arrays(state, demon["name"]),
                             alone.horde.demon_arrays(alone.horde_state(), demon["name"]), strict=True):  # fmt: skip
            np.testing.assert_allclose(ours, its, rtol=0, atol=1e-12)


# ----------------------------------------------------------------------------------------------
# 3. The engine equals the oracle


def test_the_engine_equals_the_oracle_on_a_random_stream() -> None:
    """TDRC demons of several lambdas, betas and etas, given policies and their own trace classes, a demon
    reset at every episode start and one over features conditioned on another's prediction, 600 steps with
    episode ends, cut 0; weights, h, traces and predictions to 1e-9 at every step."""
    demons = [*DEMONS,
              {"name": "forgets", "learner": "tdrc", "policy": "uniform", "cumulant": 1.0, "reset": "episode",
               "parameters": {"eta": 0.5}},
              {"name": "gated", "learner": "tdrc", "policy": {"kind": "fixed", "probabilities": [0.2, 0.8]},
               "cumulant": {"sensor": "reward"}, "continuation": {"if": {"sensor": "state"}, "then": 0.5, "else": 1},
               "features": {"kind": "table", "sensor": "state", "table": [[0], [1]],
                            "condition": {"demon": "d0", "thresholds": [0.0]}}}]  # fmt: skip
    spec = stream_spec(demons)
    loop, largest = equals_the_oracle_on_a_random_stream(spec)
    assert np.abs(loop.horde.demon_arrays(loop.horde_state(), "d1")[1]).max() > 1e-3, "h learned something"
    assert largest > 0.0


# ----------------------------------------------------------------------------------------------
# 4 and 5. Convergence off-policy to the exact answer of a chain; dropping rho misses it


def run_chain(steps: int, rho_scale: float = 1.0, seed: int = 0) -> np.ndarray:
    """One TDRC(0.5) demon (the numpy form) on the chain of test_online_learners (tabular), behaviour 50/50,
    target 80/20, alpha = alpha_h = 0.02, beta 1."""
    rng = np.random.default_rng(seed)
    params = learners.LearnerParams(np.full(1, 0.5), np.full(1, 0.02), np.full(1, 0.02), np.ones(1), np.ones(1))
    state = learners.zeros(1, CHAIN)
    s, g_t = 2, 0.0
    for _ in range(steps):
        right = rng.random() < BEHAVIOUR_RIGHT
        rho = (TARGET_RIGHT / BEHAVIOUR_RIGHT if right else (1 - TARGET_RIGHT) / (1 - BEHAVIOUR_RIGHT)) ** rho_scale
        s_next = s + (1 if right else -1)
        done = s_next < 0 or s_next >= CHAIN
        x_tp1 = (np.zeros(0, np.int64), np.zeros(0)) if done else (np.array([s_next]), np.ones(1))
        z = 1.0 if s_next >= CHAIN else 0.0
        g_tp1 = 0.0 if done else 1.0
        state, _ = learners.tdrc_update(state, params, np.ones(1), (np.array([s]), np.ones(1)), x_tp1, np.zeros(1),
                                        np.full(1, z), np.full(1, g_t), np.full(1, g_tp1), np.full(1, rho))  # fmt: skip
        s, g_t = (2, 0.0) if done else (s_next, g_tp1)
    return state.theta[0]


@pytest.mark.slow
def test_converges_off_policy_to_the_exact_answer() -> None:
    exact = exact_chain_values(TARGET_RIGHT)
    theta = np.mean([run_chain(40_000, seed=seed) for seed in (0, 1)], axis=0)
    np.testing.assert_allclose(theta, exact, atol=0.05)


@pytest.mark.slow
def test_dropping_rho_misses_the_answer() -> None:
    exact = exact_chain_values(TARGET_RIGHT)
    theta = run_chain(40_000, rho_scale=0.0)
    assert abs(theta[2] - exact[2]) > 0.1


def equals_the_oracle_on_a_random_stream(spec: Any, steps: int = 600, seed: int = 5) -> tuple[Learner, float]:
    """Step the engine (cut 0) and `reference.ReferenceHorde` through one random two-sensor stream with an episode
    end every 50 steps, asserting every demon's theta, second weights, trace and prediction equal to 1e-9 at every
    step; the engine and the largest gap seen. (Shared with test_gtd2.py.)"""
    loop, ref = Learner(Horde(spec, cut=0.0)), reference.ReferenceHorde(spec)
    rng = np.random.default_rng(seed)
    names = spec.world.sensor_names()
    first = np.array([0.0, 0.0])
    loop.observe(first)
    ref.observe(0.0, 0.0, dict(zip(names, first.tolist(), strict=True)))
    largest = 0.0
    for step in range(steps):
        action = int(rng.random() < 0.5)
        sensors = np.array([float(rng.integers(2)), rng.normal() * 0.3])
        ends = step % 50 == 49
        loop.learn(sensors, [action], [0.5], terminated=ends)
        ref.learn(action, 0.5, 0.0, 0.0, dict(zip(names, sensors.tolist(), strict=True)), ends)
        if ends:
            loop.observe(first)
            ref.observe(0.0, 0.0, dict(zip(names, first.tolist(), strict=True)))
        state = loop.horde_state()
        for i, name in enumerate(loop.horde.names):
            theta, second, e = loop.horde.demon_arrays(state, name)
            plain = ref.demons[name]
            for ours, theirs in ((theta, plain.theta), (second, plain.w), (e, plain.e),
                                 (state.prediction[i : i + 1], [plain.prediction])):  # fmt: skip
                gap = float(np.abs(ours - theirs).max())
                largest = max(largest, gap)
                assert gap < 1e-9, (step, name, ours, theirs)
    return loop, largest
