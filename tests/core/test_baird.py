"""Baird's counterexample (Sutton & Barto, 2nd ed., section 11.2).

Seven states, eight features: upper state i has 2 on feature i and 1 on feature 7; the lower state has
1 on feature 6 and 2 on feature 7. The behaviour takes the dashed action (to one of the six upper
states, uniformly) with probability 6/7 and the solid action (to the lower state) with 1/7; the target
policy always takes the solid action. Reward 0, gamma 0.99, initial weights (1, 1, 1, 1, 1, 1, 10, 1).
Off-policy semi-gradient TD's weights blow up; GTD (TDC) and GQ stay bounded and drive the mean squared
projected Bellman error, computed exactly from the MDP, towards 0.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from horde.core import learners, reference

GAMMA = 0.99
PHI = np.zeros((7, 8))  # [states, features]
for _i in range(6):
    PHI[_i, _i], PHI[_i, 7] = 2.0, 1.0
PHI[6, 6], PHI[6, 7] = 1.0, 2.0
THETA0 = np.array([1, 1, 1, 1, 1, 1, 10, 1], dtype=float)
DASHED, SOLID = 0, 1
B = np.array([6 / 7, 1 / 7])  # behaviour over (dashed, solid), the same in every state
MU = np.full(7, 1 / 7)  # the behaviour's state distribution: the next state does not depend on this one


def mspbe(features: np.ndarray, weights: np.ndarray, delta: np.ndarray) -> float:
    """||Pi delta||^2_D = (Phi' D delta)' (Phi' D Phi)^+ (Phi' D delta), D the behaviour's distribution."""
    b = features.T @ (weights * delta)
    a = features.T @ (weights[:, None] * features)
    return float(b @ np.linalg.pinv(a) @ b)


def mspbe_v(theta: np.ndarray) -> float:
    v = PHI @ theta
    delta = GAMMA * v[6] - v  # under the target policy every state moves to the lower state
    return mspbe(PHI, MU, delta)


def phi_sa(s: int, a: int) -> np.ndarray:
    out = np.zeros(16)
    out[a * 8 : (a + 1) * 8] = PHI[s]
    return out


PHI_SA = np.array([phi_sa(s, a) for s in range(7) for a in (DASHED, SOLID)])  # [(s, a), 16]
D_SA = np.array([MU[s] * B[a] for s in range(7) for a in (DASHED, SOLID)])


def mspbe_q(theta: np.ndarray) -> float:
    q = (PHI_SA @ theta).reshape(7, 2)
    # dashed: to a uniform upper state, then solid; solid: to the lower state, then solid
    expected_next = np.array([[q[:6, SOLID].mean(), q[6, SOLID]]] * 7)
    return mspbe(PHI_SA, D_SA, (GAMMA * expected_next - q).ravel())


def stream(steps: int, seed: int):
    """(s_t, a_t, s_tp1, rho_t) following the behaviour."""
    rng = np.random.default_rng(seed)
    s = int(rng.integers(7))
    for _ in range(steps):
        a = SOLID if rng.random() < B[SOLID] else DASHED
        s_next = 6 if a == SOLID else int(rng.integers(6))
        yield s, a, s_next, (1.0 / B[SOLID] if a == SOLID else 0.0)
        s = s_next


def sparse(phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    idx = np.flatnonzero(phi)
    return idx, phi[idx]


def state_value_run(steps: int, alpha: float, alpha_w: float, seed: int = 0):
    """Off-policy TD(0) and GTD(0) as one learners.update stack and as the plain reference, side by side.

    Returns:
        per checkpoint: (step, theta of the stack [2, 8], theta of the reference per kind).
    """
    p = learners.LearnerParams(
        lam=np.zeros(2),
        alpha=np.full(2, alpha),
        alpha_w=np.full(2, alpha_w),
        rho_in_trace=np.ones(2),
        correct=np.array([0.0, 1.0]),  # row 0: TD, row 1: GTD
    )
    state = learners.zeros(2, 8)._replace(theta=np.stack([THETA0, THETA0]))
    plain = {kind: (THETA0.copy(), np.zeros(8), np.zeros(8)) for kind in ("td", "gtd")}
    gamma = np.full(2, GAMMA)
    out = []
    for t, (s, _, s_next, rho) in enumerate(stream(steps, seed), start=1):
        state, _ = learners.update(
            state,
            p,
            sparse(PHI[s]),
            sparse(PHI[s_next]),
            np.zeros(2),
            np.zeros(2),
            gamma,
            gamma,
            np.full(2, rho),
        )
        for kind, step in (("td", reference.td_step), ("gtd", reference.gtd_step)):
            transition = reference.Transition(PHI[s], PHI[s_next], 0.0, 0.0, GAMMA, GAMMA, rho, 0.0)
            theta, w, e, _ = step(*plain[kind], transition, alpha, alpha_w)
            plain[kind] = (theta, w, e)
        if t % 500 == 0:
            out.append((t, state.theta.copy(), plain["td"][0].copy(), plain["gtd"][0].copy()))
    return out


@pytest.fixture(scope="module")
def state_values():
    return state_value_run(3000, alpha=0.01, alpha_w=0.1)


def test_the_engine_stack_equals_the_reference_on_baird(state_values):
    for _, stacked, td, gtd in state_values:
        np.testing.assert_allclose(stacked[0], td, rtol=1e-9)
        np.testing.assert_allclose(stacked[1], gtd, rtol=1e-9)


def test_off_policy_semi_gradient_td_blows_up(state_values):
    sizes = [np.abs(stacked[0]).max() for _, stacked, _, _ in state_values]
    assert sizes[-1] > 1e4, sizes  # from 10
    assert all(b > a for a, b in itertools.pairwise(sizes)), sizes  # and keeps growing
    assert mspbe_v(state_values[-1][1][0]) > 100 * mspbe_v(THETA0)


def test_gtd_stays_bounded_and_its_projected_bellman_error_falls(state_values):
    start = mspbe_v(THETA0)
    # By hand: each state owns a feature, so Phi has rank 7 (one per state), the projection is the identity and
    # the MSPBE at theta0 is the plain mean squared Bellman error. v = 2 + 1 = 3 in the six upper states and
    # 10 + 2 = 12 in the lower one; delta = 0.99 * 12 - v is 8.88 above and -0.12 below, each state weighted 1/7.
    assert start == pytest.approx((6 * 8.88**2 + 0.12**2) / 7, rel=1e-12)  # 67.5915...
    errors = [mspbe_v(stacked[1]) for _, stacked, _, _ in state_values]
    assert all(np.abs(stacked[1]).max() < 15 for _, stacked, _, _ in state_values)
    assert errors[0] < 0.1 * start
    assert errors[-1] < 1e-3, errors


def action_value_run(steps: int, alpha: float, alpha_w: float, seed: int = 1) -> list[tuple[float, float]]:
    """GQ(0) on state-action features; returns (max |theta|, MSPBE) every 1000 steps."""
    p = learners.LearnerParams(np.zeros(1), np.full(1, alpha), np.full(1, alpha_w), np.zeros(1), np.ones(1))
    state = learners.zeros(1, 16)._replace(theta=np.concatenate([THETA0, THETA0])[None])
    plain = (state.theta[0].copy(), np.zeros(16), np.zeros(16))
    gamma = np.full(1, GAMMA)
    out = []
    for t, (s, a, s_next, rho) in enumerate(stream(steps, seed), start=1):
        phi_bar = phi_sa(s_next, SOLID)  # the target policy takes the solid action
        state, _ = learners.update(
            state,
            p,
            sparse(phi_sa(s, a)),
            sparse(phi_bar),
            np.zeros(1),
            np.zeros(1),
            gamma,
            gamma,
            np.full(1, rho),
        )
        transition = reference.Transition(phi_sa(s, a), phi_bar, 0.0, 0.0, GAMMA, GAMMA, rho, 0.0)
        plain = reference.gq_step(*plain, transition, alpha, alpha_w)[:3]
        if t % 1000 == 0:
            np.testing.assert_allclose(state.theta[0], plain[0], rtol=1e-9)
            out.append((float(np.abs(state.theta).max()), mspbe_q(state.theta[0])))
    return out


def test_gq_on_state_action_features_stays_bounded_and_converges():
    start = mspbe_q(np.concatenate([THETA0, THETA0]))
    history = action_value_run(8000, alpha=0.005, alpha_w=0.05)
    assert all(size < 15 for size, _ in history), history
    assert history[-1][1] < 1e-3 * start, (start, history)


def test_gq_without_its_correction_blows_up():
    """alpha_w = 0 keeps w at 0, which removes the gradient correction: semi-gradient expected Sarsa."""
    history = action_value_run(8000, alpha=0.01, alpha_w=0.0)
    assert history[-1][0] > 100, history
    assert history[-1][1] > 100 * mspbe_q(np.concatenate([THETA0, THETA0]))
