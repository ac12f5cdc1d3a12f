"""True online TD(lambda), true online GTD(lambda), emphatic TD(lambda) and adaptive step sizes (TIDBD,
Autostep) in the readable numpy form (`learners.py`) against the plain oracle (`reference.py`).

The five kinds of STYLE item 8 for every learner: a case computed by hand, a stack of demons equal to the
demons one by one, the numpy form equal to the oracle, convergence to the exact answer of a small chain
(which also fails if the importance ratio is dropped: the behaviour's answer is far from the target's);
true online TD(lambda) equal to the online lambda-return algorithm written out as a forward view. The
engine's forms are checked against the oracle in test_engine_online.py.
"""

from __future__ import annotations

import numpy as np
import pytest

from horde.core import learners, reference

LEARNERS = ("true_online_td", "true_online_gtd", "etd", "tidbd", "autostep")


def numpy_step(kind: str, state: learners.OnlineState, p: dict, x_t, x_tp1, r, z, g_t, g_tp1, rho):
    """One step of a stack with the numpy form; p holds [D] parameters."""
    tail = (x_t, x_tp1, r, z, g_t, g_tp1, rho)
    if kind == "true_online_td":
        return learners.true_online_td_update(state, p["lam"], p["alpha"], *tail)
    if kind == "true_online_gtd":
        return learners.true_online_gtd_update(state, p["lam"], p["alpha"], p["alpha_w"], *tail)
    if kind == "etd":
        return learners.etd_update(state, p["lam"], p["alpha"], *tail)
    auto = np.full(len(p["lam"]), 1.0 if kind == "autostep" else 0.0)
    return learners.adaptive_td_update(state, p["lam"], auto, p["meta"], p["tau"], *tail)


class OracleDemon:
    """One demon through reference.py's step functions."""

    def __init__(self, kind: str, n: int, lam: float, alpha: float, alpha_w: float, meta: float, tau: float):
        self.kind, self.lam, self.alpha, self.alpha_w, self.meta, self.tau = kind, lam, alpha, alpha_w, meta, tau
        self.theta, self.w, self.e, self.e_grad, self.e_w = (np.zeros(n) for _ in range(5))
        self.alphas, self.h, self.v = np.full(n, alpha), np.zeros(n), np.zeros(n)
        self.v_old = self.rho_prev = self.followon = 0.0

    def step(self, x_t, x_tp1, r, z, g_t, g_tp1, rho) -> float:
        t = reference.Transition(x_t, x_tp1, r, z, g_t, g_tp1, rho, self.lam)
        if self.kind == "true_online_td":
            self.theta, self.e, self.v_old, delta = reference.true_online_td_step(
                self.theta, self.e, self.v_old, t, self.alpha
            )
        elif self.kind == "true_online_gtd":
            self.theta, self.w, self.e, self.e_grad, self.e_w, self.v_old, delta = reference.true_online_gtd_step(
                self.theta, self.w, self.e, self.e_grad, self.e_w, self.v_old, self.rho_prev, t, self.alpha,
                self.alpha_w,
            )  # fmt: skip
        elif self.kind == "etd":
            self.theta, self.e, self.followon, delta = reference.etd_step(
                self.theta, self.e, self.followon, self.rho_prev, t, self.alpha
            )
        else:
            self.theta, self.e, self.alphas, self.h, self.v, delta = reference.adaptive_td_step(
                self.theta, self.e, self.alphas, self.h, self.v, t, self.kind, self.meta, self.tau
            )
        self.rho_prev = rho
        return delta


# ----------------------------------------------------------------------------------------------
# 1. By hand


def test_true_online_td_by_hand() -> None:
    """Two steps on two features, alpha 0.5, lambda 0.5, gamma 1, rho 2 then 1, worked on paper.

    Step 1: x_t = (1, 0), x_tp1 = (0, 1), r = 1, gamma_t = 0: delta = 1; e = 2 * 0.5 (1, 0) = (1, 0);
    theta = 0 + 1 * (1, 0) + (0 - 0) (...) = (1, 0); v_old = theta_0 . x_tp1 = 0.
    Step 2: x_t = (0, 1), x_tp1 = (1, 1), r = 0, gamma_t = 1, rho = 1: v_t = 0, v_tp1 = 1, delta = 1;
    decay = 0.5, e . x_t = 0, e = 0.5 (1, 0) + 0.5 (0, 1) = (0.5, 0.5); v_t - v_old = 0 - 0 = 0;
    theta = (1, 0) + (0.5, 0.5) = (1.5, 0.5).
    """
    demon = OracleDemon("true_online_td", 2, lam=0.5, alpha=0.5, alpha_w=0.0, meta=0.0, tau=1.0)
    assert demon.step(np.array([1.0, 0]), np.array([0, 1.0]), 1.0, 0.0, 0.0, 1.0, 2.0) == pytest.approx(1.0)
    np.testing.assert_allclose(demon.theta, [1.0, 0.0])
    assert demon.step(np.array([0, 1.0]), np.array([1.0, 1.0]), 0.0, 0.0, 1.0, 1.0, 1.0) == pytest.approx(1.0)
    np.testing.assert_allclose(demon.e, [0.5, 0.5])
    np.testing.assert_allclose(demon.theta, [1.5, 0.5])
    # A third step where theta_t . x_t != theta_{t-1} . x_t: x_t = (1, 1) (v_old = theta_1 . (1, 1) = 1,
    # v_t = 2), x_tp1 = (0, 0) terminal, r = 0, gamma_t = 1, rho = 1: delta = -2; e . x_t = 1,
    # e = 0.5 (0.5, 0.5) + 0.5 (1 - 0.5 * 1) (1, 1) = (0.5, 0.5);
    # theta = (1.5, 0.5) - 2 (0.5, 0.5) + (2 - 1) ((0.5, 0.5) - 0.5 (1, 1)) = (0.5, -0.5).
    assert demon.step(np.array([1.0, 1.0]), np.zeros(2), 0.0, 0.0, 1.0, 0.0, 1.0) == pytest.approx(-2.0)
    np.testing.assert_allclose(demon.theta, [0.5, -0.5])


def test_etd_by_hand() -> None:
    """Followon and emphasis: lambda 0.5, gamma 0.5, rho 2 then 0.5, alpha 0.1, one feature.

    Step 1 (gamma_t = 0): F = 1, M = 0.5 + 0.5 = 1, e = 2 * (0 + 1) = 2; delta = r = 1; theta = 0.2.
    Step 2 (gamma_t = 0.5, rho_prev = 2): F = 2 * 0.5 * 1 + 1 = 2, M = 0.5 + 0.5 * 2 = 1.5,
    e = 0.5 (0.5 * 0.5 * 2 + 1.5) = 1.0; delta = 0 + 0.5 * 0.2 - 0.2 = -0.1; theta = 0.2 - 0.01 = 0.19.
    """
    demon = OracleDemon("etd", 1, lam=0.5, alpha=0.1, alpha_w=0.0, meta=0.0, tau=1.0)
    one = np.ones(1)
    demon.step(one, one, 1.0, 0.0, 0.0, 0.5, 2.0)
    assert (demon.followon, demon.e[0], demon.theta[0]) == pytest.approx((1.0, 2.0, 0.2))
    demon.step(one, one, 0.0, 0.0, 0.5, 0.5, 0.5)
    assert (demon.followon, demon.e[0], demon.theta[0]) == pytest.approx((2.0, 1.0, 0.19))


def test_true_online_gtd_by_hand() -> None:
    """One feature, alpha 0.5, alpha_w 0.25, lambda 0, gamma 1.

    Step 1 (gamma_t = 0, rho 2): x_t = x_tp1 = 1, r = 1: delta = 1; e = 2 * 0.5 = 1; e_grad = 2;
    e_w = 0.25; theta = 0 + 1 * 1 + 0 - 0.5 * 1 * 1 * (0 * 2) = 1; w = 0 + 2 * 1 * 0.25 - 0 = 0.5; v_old = 0.
    Step 2 (gamma_t = 1 but lambda 0, rho 1): r = 0: v_t = 1, v_tp1 = 1, delta = 0; e = 0.5; e_grad = 1;
    e_w = 0.25; theta = 1 + 0 + (1 - 0) (0.5 - 0.5) - 0.5 * 1 * 1 * (0.5 * 1) = 0.75;
    w = 0.5 + 0 - 0.25 * 0.5 = 0.375.
    """
    demon = OracleDemon("true_online_gtd", 1, lam=0.0, alpha=0.5, alpha_w=0.25, meta=0.0, tau=1.0)
    one = np.ones(1)
    demon.step(one, one, 1.0, 0.0, 0.0, 1.0, 2.0)
    assert (demon.theta[0], demon.w[0], demon.e_grad[0], demon.e_w[0]) == pytest.approx((1.0, 0.5, 2.0, 0.25))
    demon.step(one, one, 0.0, 0.0, 1.0, 1.0, 1.0)
    assert (demon.theta[0], demon.w[0]) == pytest.approx((0.75, 0.375))


def test_tidbd_and_autostep_by_hand() -> None:
    """One feature, initial alpha 0.5, meta step 1, lambda 0, rho 1, x = 1 always, gamma 0 (bandit).

    TIDBD. Step 1: r = 1, delta = 1, h = 0 so alpha stays 0.5; theta = 0.5; h = 0 * 0.5 + 0.5 = 0.5.
    Step 2: r = 1, delta = 0.5; alpha = 0.5 exp(0.5 * 0.5) = 0.5 e^0.25; theta = 0.5 + 0.5 alpha.
    Autostep. Step 1 as TIDBD (v = max(0, 0 + ...) = 0). Step 2: sample = 0.25, v = max(0.25, ...) = 0.25,
    alpha = 0.5 e^1 = 1.359; effective step alpha e (x - 0) = 1.359 > 1: alpha = 1; theta = 0.5 + 0.5 = 1,
    the target exactly: the normalisation stops the overshoot that TIDBD's 0.642 step size would not.
    """
    one, zero = np.ones(1), np.zeros(1)
    tidbd = OracleDemon("tidbd", 1, lam=0.0, alpha=0.5, alpha_w=0.0, meta=1.0, tau=100.0)
    auto = OracleDemon("autostep", 1, lam=0.0, alpha=0.5, alpha_w=0.0, meta=1.0, tau=100.0)
    for demon in (tidbd, auto):
        demon.step(one, zero, 1.0, 0.0, 0.0, 0.0, 1.0)
        assert (demon.alphas[0], demon.theta[0], demon.h[0]) == pytest.approx((0.5, 0.5, 0.5))
        demon.step(one, zero, 1.0, 0.0, 0.0, 0.0, 1.0)
    alpha = 0.5 * np.exp(0.25)
    assert (tidbd.alphas[0], tidbd.theta[0]) == pytest.approx((alpha, 0.5 + 0.5 * alpha))
    assert (auto.v[0], auto.alphas[0], auto.theta[0]) == pytest.approx((0.25, 1.0, 1.0))


# ----------------------------------------------------------------------------------------------
# 2 and 3. A stack equals its demons one by one; the numpy form equals the oracle


@pytest.mark.parametrize("kind", LEARNERS)
def test_stack_equals_oracle_demon_by_demon(kind: str) -> None:
    rng = np.random.default_rng(7)
    demons, n, steps = 4, 6, 300
    p = {
        "lam": np.array([0.0, 0.5, 0.9, 1.0]),
        "alpha": np.array([0.05, 0.02, 0.1, 0.01]),
        "alpha_w": np.array([0.01, 0.0, 0.02, 0.005]),
        "meta": np.array([0.0, 0.01, 0.05, 0.1]),
        "tau": 50.0,
    }
    state = learners.online_zeros(demons, n, p["alpha"] if kind in ("tidbd", "autostep") else None)
    oracle = [
        OracleDemon(kind, n, p["lam"][d], p["alpha"][d], p["alpha_w"][d], p["meta"][d], p["tau"]) for d in range(demons)
    ]
    x_t = (rng.random(n) < 0.4).astype(float)
    g_t = np.zeros(demons)
    for _ in range(steps):
        x_tp1 = (rng.random(n) < 0.4).astype(float) * rng.choice([1.0, 0.5])
        r, z = rng.normal(size=demons), rng.normal(size=demons)
        g_tp1 = rng.choice([0.0, 0.8, 1.0], size=demons)
        rho = rng.choice([0.0, 0.5, 2.0], size=demons)
        state, delta = numpy_step(kind, state, p, x_t, x_tp1, r, z, g_t, g_tp1, rho)
        for d, demon in enumerate(oracle):
            assert demon.step(x_t, x_tp1, r[d], z[d], g_t[d], g_tp1[d], rho[d]) == pytest.approx(delta[d], abs=1e-9)
        x_t, g_t = x_tp1, g_tp1
    for d, demon in enumerate(oracle):
        np.testing.assert_allclose(state.theta[d], demon.theta, atol=1e-9)
    assert np.isfinite(state.theta).all()


# ----------------------------------------------------------------------------------------------
# True online TD(lambda) is the online lambda-return algorithm (van Seijen et al. 2016, Theorem 1)


def online_lambda_return(features: np.ndarray, rewards: np.ndarray, gamma: float, lam: float, alpha: float):
    """The forward view, written from its definition: for every horizon h, redo the updates of steps
    0..h-1 from theta_0 towards the truncated lambda-returns G_k^{lambda|h}, whose n-step returns bootstrap
    from the latest weights theta_{k+n-1}^{k+n-1}. features [T + 1, n] (the last one terminal, value 0).

    Returns: [T + 1, n] the weights theta_h^h of each horizon.
    """
    steps, n = len(rewards), features.shape[1]
    latest = [np.zeros(n)]  # theta_h^h
    for h in range(1, steps + 1):

        def value(t: int) -> float:
            return 0.0 if t == steps else float(latest[t - 1] @ features[t])

        theta = np.zeros(n)
        for k in range(h):

            def n_step(m: int) -> float:
                g = sum(gamma**i * rewards[k + i] for i in range(m))  # noqa: B023
                return g + gamma**m * value(k + m)  # noqa: B023

            horizon = h - k
            target = (1 - lam) * sum(lam ** (m - 1) * n_step(m) for m in range(1, horizon)) + lam ** (
                horizon - 1
            ) * n_step(horizon)
            theta = theta + alpha * (target - theta @ features[k]) * features[k]
        latest.append(theta)
    return np.array(latest)


def test_true_online_td_equals_the_online_lambda_return() -> None:
    rng = np.random.default_rng(3)
    steps, n, gamma, lam, alpha = 7, 4, 0.9, 0.7, 0.3
    features = rng.random((steps + 1, n))
    features[-1] = 0.0
    rewards = rng.normal(size=steps)
    expected = online_lambda_return(features, rewards, gamma, lam, alpha)
    demon = OracleDemon("true_online_td", n, lam, alpha, 0.0, 0.0, 1.0)
    g_t = 0.0
    for t in range(steps):
        g_tp1 = 0.0 if t + 1 == steps else gamma
        demon.step(features[t], features[t + 1], rewards[t], 0.0, g_t, g_tp1, 1.0)
        g_t = g_tp1
        np.testing.assert_allclose(demon.theta, expected[t + 1], atol=1e-12)
    # Conventional TD(lambda) does not match it: the equivalence is what the dutch trace buys.
    theta, e = np.zeros(n), np.zeros(n)
    g_t = 0.0
    for t in range(steps):
        g_tp1 = 0.0 if t + 1 == steps else gamma
        transition = reference.Transition(features[t], features[t + 1], rewards[t], 0.0, g_t, g_tp1, 1.0, lam)
        theta, _, e, _ = reference.td_step(theta, theta, e, transition, alpha, 0.0)
        g_t = g_tp1
    assert np.abs(theta - expected[-1]).max() > 1e-3


# ----------------------------------------------------------------------------------------------
# 4 and 5. Convergence off-policy to the exact answer of a chain; dropping rho would miss it


CHAIN = 5  # states 0..4; left of 0 ends with 0, right of 4 ends with 1
TARGET_RIGHT, BEHAVIOUR_RIGHT = 0.8, 0.5


def exact_chain_values(p_right: float) -> np.ndarray:
    """v(s) = p v(s+1) + (1 - p) v(s-1), with v(-1) = 0 and v(5) = 1 (the probability of leaving right)."""
    a, b = np.eye(CHAIN), np.zeros(CHAIN)
    for s in range(CHAIN):
        if s + 1 < CHAIN:
            a[s, s + 1] -= p_right
        else:
            b[s] += p_right
        if s > 0:
            a[s, s - 1] -= 1 - p_right
    return np.linalg.solve(a, b)


def run_chain(kind: str, steps: int, rho_scale: float = 1.0, seed: int = 0) -> np.ndarray:
    """A stack of one demon of `kind` on the chain (tabular features), behaviour 50/50, target 80/20."""
    rng = np.random.default_rng(seed)
    eye = np.eye(CHAIN)
    small = kind in ("tidbd", "autostep")
    p = {"lam": np.array([0.5]), "alpha": np.array([0.02 if not small else 0.05]), "alpha_w": np.array([0.005]),
         "meta": np.array([0.01]), "tau": 1e4}  # fmt: skip
    state = learners.online_zeros(1, CHAIN, p["alpha"] if small else None)
    s, g_t = 2, np.zeros(1)
    for _ in range(steps):
        right = rng.random() < BEHAVIOUR_RIGHT
        rho = (TARGET_RIGHT / BEHAVIOUR_RIGHT if right else (1 - TARGET_RIGHT) / (1 - BEHAVIOUR_RIGHT)) ** rho_scale
        s_next = s + (1 if right else -1)
        done = s_next < 0 or s_next >= CHAIN
        x_tp1 = np.zeros(CHAIN) if done else eye[s_next]
        z = np.array([1.0 if s_next >= CHAIN else 0.0])
        g_tp1 = np.zeros(1) if done else np.ones(1)
        state, _ = numpy_step(kind, state, p, eye[s], x_tp1, np.zeros(1), z, g_t, g_tp1, np.array([rho]))
        s, g_t = (2, np.zeros(1)) if done else (s_next, g_tp1)
    return state.theta[0]


@pytest.mark.slow
@pytest.mark.parametrize("kind", LEARNERS)
def test_converges_off_policy_to_the_exact_answer(kind: str) -> None:
    """Averaged over the last steps' noise by taking two seeds; within 0.05 of the exact probabilities."""
    exact = exact_chain_values(TARGET_RIGHT)
    theta = np.mean([run_chain(kind, 40_000, seed=seed) for seed in (0, 1)], axis=0)
    np.testing.assert_allclose(theta, exact, atol=0.05)


@pytest.mark.slow
@pytest.mark.parametrize("kind", LEARNERS)
def test_dropping_rho_misses_the_answer(kind: str) -> None:
    """rho ** 0 = 1: the demon learns the behaviour's answer, at least 0.1 away from the target's in state 2."""
    exact = exact_chain_values(TARGET_RIGHT)
    assert abs(exact_chain_values(BEHAVIOUR_RIGHT)[2] - exact[2]) > 0.2
    theta = run_chain(kind, 40_000, rho_scale=0.0)
    assert abs(theta[2] - exact[2]) > 0.1


# ----------------------------------------------------------------------------------------------
# Baird's counterexample: emphatic TD stays bounded where off-policy TD diverges


def test_emphatic_td_is_stable_on_bairds_counterexample_where_td_diverges() -> None:
    """The expected updates (Sutton, Mahmood & White 2016, section 5; Sutton & Barto 2018, figure 11.6):
    the sample ETD's followon trace has infinite variance on Baird's star (rho = 7, gamma = 0.99), so the
    paper, the book and this test step with the expectation over the behaviour's transitions. Each
    transition's update comes from `learners.etd_update` / `reference.td_step` themselves, with the followon
    trace set to its expectation in that state: f(s) / d(s) = 1 in the upper states (nothing leads there under
    the target policy) and (1 + 6 gamma) / (1 - gamma) in the lower one.
    """
    from tests.core.test_baird import GAMMA, PHI, SOLID, THETA0, B, mspbe_v

    followon = np.array([1.0] * 6 + [(1 + 6 * GAMMA) / (1 - GAMMA)])  # E[F_t | S_t = s], lambda = 0: M = F
    rho, alpha = 1.0 / B[SOLID], 0.01  # the dashed action has rho = 0 and moves nothing

    def expected_step(theta: np.ndarray, emphatic: bool) -> np.ndarray:
        total = np.zeros_like(theta)
        for s in range(7):
            if emphatic:
                state = learners.online_zeros(1, 8)._replace(
                    theta=theta[None].copy(), followon=np.array([followon[s] - 1.0]), rho_prev=np.ones(1)
                )
                lam, step = np.zeros(1), np.array([alpha])
                zero, one, gamma, ratio = np.zeros(1), np.ones(1), np.array([GAMMA]), np.array([rho])
                new = learners.etd_update(state, lam, step, PHI[s], PHI[6], zero, zero, one, gamma, ratio)[0].theta[0]
            else:
                transition = reference.Transition(PHI[s], PHI[6], 0.0, 0.0, 0.0, GAMMA, rho, 0.0)
                new = reference.td_step(theta, theta, np.zeros(8), transition, alpha, 0.0)[0]
            total += B[SOLID] / 7 * (new - theta)  # d(s) b(solid | s)
        return theta + total

    td, etd = THETA0.copy(), THETA0.copy()
    for _ in range(2000):
        td, etd = expected_step(td, False), expected_step(etd, True)
        assert np.abs(etd).max() < 2 * np.abs(THETA0).max()
    assert np.abs(td).max() > 1000, "off-policy TD diverges on Baird's counterexample"
    assert mspbe_v(etd) < 1e-15 < mspbe_v(THETA0), "ETD drives the projected Bellman error to zero"
