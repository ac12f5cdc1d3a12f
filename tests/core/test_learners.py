"""GQ(lambda), GTD(lambda), TD(lambda) over stacked demons (DESIGN section 5).

Three kinds of test: a tiny case computed by hand, a stack of D demons equal to D single demons, and
the stacked sparse update equal to the plain dense equations of `reference.py` on random inputs.
"""

from __future__ import annotations

import numpy as np
import pytest

from horde.core import learners, reference

KINDS = {"gq": (0.0, 1.0), "gtd": (1.0, 1.0), "td": (1.0, 0.0)}  # (rho_in_trace, correct)


def params(kinds: list[str], lam, alpha, alpha_w) -> learners.LearnerParams:
    d = len(kinds)
    return learners.LearnerParams(
        lam=np.broadcast_to(np.asarray(lam, dtype=float), (d,)).copy(),
        alpha=np.broadcast_to(np.asarray(alpha, dtype=float), (d,)).copy(),
        alpha_w=np.broadcast_to(np.asarray(alpha_w, dtype=float), (d,)).copy(),
        rho_in_trace=np.array([KINDS[k][0] for k in kinds]),
        correct=np.array([KINDS[k][1] for k in kinds]),
    )


def one(value: float) -> np.ndarray:
    return np.array([value])


def test_tiny_gq_lambda_case_by_hand():
    """Two steps of GQ(lambda) for one demon over 4 binary features, every number written out.

    lambda = 0.5, alpha = 0.5, alpha_w = 0.25.

    Step 1 (episode start, all zero): phi_t = [1,0,0,0], phi_bar = [0,0,.5,.5], r = 1, z = 0,
    gamma_t = 0, gamma_tp1 = 1, rho = 1.
        delta = 1 + 0 + 1 * 0 - 0 = 1
        e     = phi_t = [1, 0, 0, 0]
        theta = 0 + 0.5 * (1 * e - 1 * 0.5 * (w.e = 0) * phi_bar) = [0.5, 0, 0, 0]
        w     = 0 + 0.25 * (1 * e - (w.phi_t = 0) * phi_t) = [0.25, 0, 0, 0]

    Step 2: phi_t = [0,0,1,0], phi_bar = [.5,.5,0,0], r = 0, z = 0, gamma_t = 1, gamma_tp1 = 1, rho = 2.
        delta = 0 + 0 + 1 * (0.5 * 0.5 + 0.5 * 0) - 0 = 0.25
        e     = [0,0,1,0] + 1 * 0.5 * 2 * [1,0,0,0] = [1, 0, 1, 0]
        w.e   = 0.25
        theta = [0.5,0,0,0] + 0.5 * (0.25 * [1,0,1,0] - 1 * 0.5 * 0.25 * [.5,.5,0,0])
              = [0.5,0,0,0] + 0.5 * [0.1875, -0.0625, 0.25, 0] = [0.59375, -0.03125, 0.125, 0]
        w     = [0.25,0,0,0] + 0.25 * (0.25 * [1,0,1,0] - 0 * phi_t) = [0.3125, 0, 0.0625, 0]
    """
    p = params(["gq"], 0.5, 0.5, 0.25)
    state = learners.zeros(1, 4)
    state, delta = learners.update(
        state, p, (np.array([0]), np.ones(1)), (np.array([2, 3]), np.array([[0.5, 0.5]])),
        one(1.0), one(0.0), one(0.0), one(1.0), one(1.0),
    )  # fmt: skip
    assert delta.tolist() == [1.0]
    assert state.e.tolist() == [[1, 0, 0, 0]]
    assert state.theta.tolist() == [[0.5, 0, 0, 0]]
    assert state.w.tolist() == [[0.25, 0, 0, 0]]
    state, delta = learners.update(
        state, p, (np.array([2]), np.ones(1)), (np.array([0, 1]), np.array([[0.5, 0.5]])),
        one(0.0), one(0.0), one(1.0), one(1.0), one(2.0),
    )  # fmt: skip
    assert delta.tolist() == [0.25]
    assert state.e.tolist() == [[1, 0, 1, 0]]
    np.testing.assert_allclose(state.theta, [[0.59375, -0.03125, 0.125, 0]], atol=1e-15)
    np.testing.assert_allclose(state.w, [[0.3125, 0, 0.0625, 0]], atol=1e-15)


def test_outcome_counts_where_continuation_stops():
    """delta_t = r + (1 - gamma_tp1) z + gamma_tp1 theta.phi_bar - theta.phi_t: z counts as gamma falls."""
    p = params(["gtd", "gtd", "gtd"], 0.0, 1.0, 0.0)
    state = learners.zeros(3, 2)._replace(theta=np.array([[0.0, 4.0]] * 3))
    gamma_tp1 = np.array([1.0, 0.25, 0.0])
    _, delta = learners.update(
        state, p, (np.array([0]), np.ones(1)), (np.array([1]), np.ones(1)),
        np.ones(3), np.full(3, 10.0), np.ones(3), gamma_tp1, np.ones(3),
    )  # fmt: skip
    # 1 + 0 * 10 + 1 * 4 = 5;  1 + 0.75 * 10 + 0.25 * 4 = 9.5;  1 + 10 + 0 = 11
    assert delta.tolist() == [5.0, 9.5, 11.0]


def random_step(rng: np.random.Generator, d: int, n: int, k: int, m: int, action_values: bool):
    idx = rng.choice(n, size=k, replace=False)
    val = rng.uniform(0.2, 1.5, size=k)
    bar_idx = rng.choice(n, size=m, replace=False)
    bar_val = rng.uniform(0.0, 1.0, size=(d, m)) if action_values else rng.uniform(0.2, 1.5, size=m)
    return (
        (idx, val),
        (bar_idx, bar_val),
        rng.normal(size=d),  # r_tp1
        rng.normal(size=d),  # z_tp1
        rng.uniform(0, 1, size=d),  # gamma_tp1
        rng.choice([0.0, 0.5, 1.0, 2.0, 4.0], size=d),  # rho_t
    )


def dense(idx: np.ndarray, val: np.ndarray, n: int) -> np.ndarray:
    out = np.zeros(n)
    out[idx] = val
    return out


@pytest.mark.parametrize("kinds", [["gq"] * 5, ["gtd"] * 5, ["td"] * 5, ["gq", "gtd", "td", "gtd", "gq"]])
def test_a_stack_of_demons_equals_each_demon_alone(kinds):
    rng = np.random.default_rng(1)
    d, n, k, m = len(kinds), 20, 5, 8
    action_values = "gq" in kinds
    p = params(kinds, rng.uniform(0, 1, d), rng.uniform(0.01, 0.2, d), rng.uniform(0.0, 0.1, d))
    stack = learners.zeros(d, n)
    singles = [learners.zeros(1, n) for _ in range(d)]
    gamma_t = np.zeros(d)
    for _ in range(30):
        x_t, (bar_idx, bar_val), r, z, gamma_tp1, rho = random_step(rng, d, n, k, m, action_values)
        stack, delta = learners.update(stack, p, x_t, (bar_idx, bar_val), r, z, gamma_t, gamma_tp1, rho)
        for i in range(d):
            pi = learners.LearnerParams(*(a[i : i + 1] for a in p))
            vi = bar_val[i : i + 1] if bar_val.ndim == 2 else bar_val
            sl = slice(i, i + 1)
            singles[i], di = learners.update(
                singles[i], pi, x_t, (bar_idx, vi), r[sl], z[sl], gamma_t[sl], gamma_tp1[sl], rho[sl]
            )
            assert di[0] == pytest.approx(delta[i], rel=1e-12, abs=1e-12)
        gamma_t = gamma_tp1
    for i in range(d):
        np.testing.assert_allclose(stack.theta[i], singles[i].theta[0], rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(stack.w[i], singles[i].w[0], rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(stack.e[i], singles[i].e[0], rtol=1e-12, atol=1e-12)
    assert np.abs(stack.theta).max() > 0.01  # the demons learned something


@pytest.mark.parametrize("kind", ["gq", "gtd", "td"])
@pytest.mark.parametrize("seed", range(5))
def test_update_equals_the_reference_equations(kind, seed):
    """Random streams with real-valued (not just binary) features and traces that carry across steps."""
    rng = np.random.default_rng(100 + seed)
    d, n, k, m = 3, 12, 6, 8
    action_values = kind == "gq"
    lam, alpha, alpha_w = rng.uniform(0, 1, d), rng.uniform(0.01, 0.1, d), rng.uniform(0.001, 0.1, d)
    p = params([kind] * d, lam, alpha, alpha_w)
    state = learners.zeros(d, n)
    plain = [(np.zeros(n), np.zeros(n), np.zeros(n)) for _ in range(d)]
    gamma_t = np.zeros(d)
    step = reference.STEPS[kind]
    for _ in range(40):
        (idx, val), (bar_idx, bar_val), r, z, gamma_tp1, rho = random_step(rng, d, n, k, m, action_values)
        state, delta = learners.update(state, p, (idx, val), (bar_idx, bar_val), r, z, gamma_t, gamma_tp1, rho)
        phi_t = dense(idx, val, n)
        for i in range(d):
            phi_bar = dense(bar_idx, bar_val[i] if action_values else bar_val, n)
            transition = reference.Transition(phi_t, phi_bar, r[i], z[i], gamma_t[i], gamma_tp1[i], rho[i], lam[i])
            theta, w, e, di = step(*plain[i], transition, alpha[i], alpha_w[i])
            plain[i] = (theta, w, e)
            assert delta[i] == pytest.approx(di, rel=1e-9, abs=1e-9)
        gamma_t = gamma_tp1
        for i in range(d):
            np.testing.assert_allclose(state.theta[i], plain[i][0], rtol=1e-9, atol=1e-9)
            np.testing.assert_allclose(state.w[i], plain[i][1], rtol=1e-9, atol=1e-9)
            np.testing.assert_allclose(state.e[i], plain[i][2], rtol=1e-9, atol=1e-9)
    assert np.abs(state.theta).max() > 0.01
    if kind == "td":
        assert not state.w.any()  # TD has no secondary weights


def test_update_is_pure():
    rng = np.random.default_rng(3)
    p = params(["gq", "gtd"], 0.9, 0.1, 0.05)
    state = learners.LearnerState(rng.normal(size=(2, 10)), rng.normal(size=(2, 10)), rng.normal(size=(2, 10)))
    before = [a.copy() for a in state]
    x_t = (np.array([1, 4, 7]), np.ones(3))
    x_bar = (np.array([0, 2]), np.full((2, 2), 0.5))
    new, _ = learners.update(state, p, x_t, x_bar, np.ones(2), np.zeros(2), np.ones(2), np.ones(2), np.ones(2))
    for old, now in zip(before, state, strict=True):
        np.testing.assert_array_equal(old, now)
    assert not np.array_equal(new.theta, state.theta)


def test_shapes_are_checked_where_arrays_enter():
    p = params(["gq", "gq"], 0.9, 0.1, 0.05)
    state = learners.zeros(2, 10)
    x_t = (np.array([1, 4]), np.ones(2))
    x_bar = (np.array([0]), np.ones((2, 1)))
    # Each per-demon argument in turn gets a wrong shape; the error names that argument and no other
    # (anchored: "gamma_t" must not pass for "gamma_tp1").
    names = ("r_tp1", "z_tp1", "gamma_t", "gamma_tp1", "rho_t")
    for wrong, name in enumerate(names):
        args = [np.ones(1) if i == wrong else np.ones(2) for i in range(len(names))]
        with pytest.raises(ValueError, match=rf"^{name} has shape \(1,\), expected \(2,\)$"):
            learners.update(state, p, x_t, x_bar, *args)
    with pytest.raises(ValueError, match="x_t values"):
        learners.update(state, p, (np.array([1, 4]), np.ones(3)), x_bar, *[np.ones(2)] * 5)
