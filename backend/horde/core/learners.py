"""GQ(lambda), GTD(lambda) and off-policy TD(lambda) over a stack of demons: the readable numpy form.

The engine (`fast.py`, `scale_fast.py`) runs these equations compiled, over blocks with shared traces
and binary features; this module writes them as pure numpy functions over any feature values (Baird's
counterexample needs real-valued ones), and `reference.py` writes them plainly, demon by demon.

All demons of a stack share one active feature set (they share a feature spec), so features enter as
sparse index arrays, while every other quantity has a leading demon axis [D]. The functions are pure:
they return a new `LearnerState` and never change their arguments.

Time indices follow one convention everywhere: `x_t` are the features of (s_t, a_t), `x_bar_tp1` the
expected next features, `gamma_t` the continuation at s_t, `gamma_tp1` at s_{t+1}.

GQ(lambda) (Maei & Sutton, 2010), per demon:
    delta_t = r_tp1 + (1 - gamma_tp1) z_tp1 + gamma_tp1 theta . x_bar_tp1 - theta . x_t
    e_t     = x_t + gamma_t lambda rho_t e_{t-1}
    theta  += alpha   (delta_t e_t - gamma_tp1 (1 - lambda) (w . e_t) x_bar_tp1)
    w      += alpha_w (delta_t e_t - (w . x_t) x_t)
GTD(lambda) is the state-value form: e_t = rho_t (x_t + gamma_t lambda e_{t-1}), x_bar_tp1 = phi(s_{t+1}).
TD(lambda) (semi-gradient, off-policy) is GTD(lambda) without the correction term and without w.
The thesis printed the w update with phi_{t+1} and one shared step size: both are errors.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class LearnerState(NamedTuple):
    """Weights of D demons over n features."""

    theta: np.ndarray  # [D, n] primary weights
    w: np.ndarray  # [D, n] secondary weights (gradient correction)
    e: np.ndarray  # [D, n] eligibility traces


class LearnerParams(NamedTuple):
    """Per-demon constants of the answer."""

    lam: np.ndarray  # [D] trace decay lambda
    alpha: np.ndarray  # [D] step size of theta (already divided by the number of active features)
    alpha_w: np.ndarray  # [D] step size of w
    rho_in_trace: np.ndarray  # [D] 1.0 for GTD/TD (e = rho (x + ...)), 0.0 for GQ (e = x + rho ...)
    correct: np.ndarray  # [D] 1.0 for GQ/GTD, 0.0 for TD (no gradient correction)


def zeros(num_demons: int, num_features: int) -> LearnerState:
    shape = (num_demons, num_features)
    return LearnerState(np.zeros(shape), np.zeros(shape), np.zeros(shape))


def _check(name: str, array: np.ndarray, shape: tuple[int, ...]) -> None:
    """The one shape check at the entry of the core's learning functions."""
    if array.shape != shape:
        raise ValueError(f"{name} has shape {array.shape}, expected {shape}")


def dot_sparse(weights: np.ndarray, idx: np.ndarray, val: np.ndarray) -> np.ndarray:
    """weights . x for a sparse x: [D, n], [m], [m] or [D, m] -> [D]."""
    return (weights[:, idx] * val).sum(axis=1)


def update(
    state: LearnerState,
    params: LearnerParams,
    x_t: tuple[np.ndarray, np.ndarray],
    x_bar_tp1: tuple[np.ndarray, np.ndarray],
    r_tp1: np.ndarray,
    z_tp1: np.ndarray,
    gamma_t: np.ndarray,
    gamma_tp1: np.ndarray,
    rho_t: np.ndarray,
) -> tuple[LearnerState, np.ndarray]:
    """One GQ(lambda) / GTD(lambda) / TD(lambda) step for every demon of the stack.

    Args:
        state: weights and traces, [D, n] each.
        params: per-demon constants, [D] each.
        x_t: (indices [k], values [k]) of phi_t, shared by all demons, indices distinct.
        x_bar_tp1: (indices [m], values [D, m] or [m]) of the expected next features, indices distinct.
        r_tp1, z_tp1: [D] cumulant and outcome at s_{t+1}.
        gamma_t, gamma_tp1: [D] continuations at s_t and s_{t+1}.
        rho_t: [D] importance ratio pi(a_t | s_t) / b(a_t | s_t).

    Returns:
        (new state, delta_t [D]).
    """
    theta, w, e = state
    num_demons = theta.shape[0]
    idx, val = x_t
    bar_idx, bar_val = x_bar_tp1
    for name, array in (("r_tp1", r_tp1), ("z_tp1", z_tp1), ("gamma_t", gamma_t), ("gamma_tp1", gamma_tp1)):
        _check(name, array, (num_demons,))
    _check("rho_t", rho_t, (num_demons,))
    _check("x_t values", val, idx.shape)

    delta = (
        r_tp1
        + (1.0 - gamma_tp1) * z_tp1
        + gamma_tp1 * dot_sparse(theta, bar_idx, bar_val)
        - dot_sparse(theta, idx, val)
    )  # [D]
    trace_scale = np.where(params.rho_in_trace > 0.0, rho_t, 1.0)  # [D]
    e = e * (gamma_t * params.lam * rho_t)[:, None]  # [D, n]
    e[:, idx] += trace_scale[:, None] * val
    w_dot_e = (w * e).sum(axis=1)  # [D]
    w_dot_x = dot_sparse(w, idx, val)  # [D]

    theta = theta + (params.alpha * delta)[:, None] * e
    correction = params.alpha * params.correct * gamma_tp1 * (1.0 - params.lam) * w_dot_e  # [D]
    theta[:, bar_idx] -= correction[:, None] * bar_val

    step_w = params.alpha_w * params.correct  # [D]
    w = w + (step_w * delta)[:, None] * e
    w[:, idx] -= (step_w * w_dot_x)[:, None] * val
    return LearnerState(theta, w, e), delta


# ----------------------------------------------------------------------------------------------
# Learners that need less tuning (README "Learners and step sizes"): true online TD(lambda), true online
# GTD(lambda), emphatic TD(lambda), and TD(lambda) with per-weight step sizes (TIDBD, Autostep). Dense
# feature values x_t, x_tp1 of shape [n] (shared by the stack) and everything else with a leading demon
# axis [D]; `reference.py` writes the same equations for one demon.


class OnlineState(NamedTuple):
    """State of the learners below; each uses the fields it needs and passes the others through."""

    theta: np.ndarray  # [D, n]
    w: np.ndarray  # [D, n] true online GTD's secondary weights; adaptive TD's h
    e: np.ndarray  # [D, n] the trace of theta (dutch for the true online learners)
    e_grad: np.ndarray  # [D, n] true online GTD: the correction's trace; autostep: the normaliser v
    e_w: np.ndarray  # [D, n] true online GTD: w's dutch trace; adaptive TD: per-weight step sizes
    v_old: np.ndarray  # [D] true online: theta_{t-1} . x_t
    rho_prev: np.ndarray  # [D] rho_{t-1}
    followon: np.ndarray  # [D] ETD's F


def online_zeros(num_demons: int, num_features: int, alpha: np.ndarray | None = None) -> OnlineState:
    """Zero weights and traces; per-weight step sizes (adaptive TD) start at alpha [D]."""
    shape = (num_demons, num_features)
    start = np.zeros(shape) if alpha is None else np.repeat(np.asarray(alpha, float)[:, None], num_features, axis=1)
    return OnlineState(np.zeros(shape), np.zeros(shape), np.zeros(shape), np.zeros(shape), start,
                       np.zeros(num_demons), np.zeros(num_demons), np.zeros(num_demons))  # fmt: skip


def _target(
    state: OnlineState, x_t: np.ndarray, x_tp1: np.ndarray, r_tp1: np.ndarray, z_tp1: np.ndarray,
    gamma_tp1: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """(theta . x_t, theta . x_tp1, delta_t), each [D]."""
    v_t, v_tp1 = state.theta @ x_t, state.theta @ x_tp1  # [D]
    return v_t, v_tp1, r_tp1 + (1.0 - gamma_tp1) * z_tp1 + gamma_tp1 * v_tp1 - v_t


def _check_online(state: OnlineState, x_t: np.ndarray, *per_demon: np.ndarray) -> None:
    num_demons, n = state.theta.shape
    _check("x_t", x_t, (n,))
    for i, array in enumerate(per_demon):
        _check(f"argument {i + 3}", array, (num_demons,))


def true_online_td_update(
    state: OnlineState, lam: np.ndarray, alpha: np.ndarray, x_t: np.ndarray, x_tp1: np.ndarray,
    r_tp1: np.ndarray, z_tp1: np.ndarray, gamma_t: np.ndarray, gamma_tp1: np.ndarray, rho_t: np.ndarray,
) -> tuple[OnlineState, np.ndarray]:  # fmt: skip
    """True online TD(lambda), off-policy dutch-trace form (van Hasselt, Mahmood & Sutton 2014; van Seijen
    et al. 2016, JMLR 17(145)):
        e_t    = rho_t (gamma_t lambda e_{t-1} + alpha (1 - rho_t gamma_t lambda e_{t-1} . x_t) x_t)
        theta += delta_t e_t + (theta_t . x_t - theta_{t-1} . x_t) (e_t - alpha rho_t x_t)

    Args: state [D, n] arrays; lam, alpha, r_tp1, z_tp1, gamma_t, gamma_tp1, rho_t [D]; x_t, x_tp1 [n].
    Returns: (new state, delta_t [D]).
    """
    _check_online(state, x_t, lam, alpha, r_tp1, z_tp1, gamma_t, gamma_tp1, rho_t)
    v_t, v_tp1, delta = _target(state, x_t, x_tp1, r_tp1, z_tp1, gamma_tp1)
    decay = rho_t * gamma_t * lam  # [D]
    e = decay[:, None] * state.e + (rho_t * alpha * (1.0 - decay * (state.e @ x_t)))[:, None] * x_t  # [D, n]
    theta = state.theta + delta[:, None] * e + (v_t - state.v_old)[:, None] * (e - (alpha * rho_t)[:, None] * x_t)
    return state._replace(theta=theta, e=e, v_old=v_tp1, rho_prev=rho_t), delta


def true_online_gtd_update(
    state: OnlineState, lam: np.ndarray, alpha: np.ndarray, alpha_w: np.ndarray, x_t: np.ndarray,
    x_tp1: np.ndarray, r_tp1: np.ndarray, z_tp1: np.ndarray, gamma_t: np.ndarray, gamma_tp1: np.ndarray,
    rho_t: np.ndarray,
) -> tuple[OnlineState, np.ndarray]:  # fmt: skip
    """True online GTD(lambda) (van Hasselt, Mahmood & Sutton 2014, Algorithm 2), constant lambda:
        e_t      = rho_t (gamma_t lambda e_{t-1} + alpha (1 - rho_t gamma_t lambda e_{t-1} . x_t) x_t)
        e_grad_t = rho_t (gamma_t lambda e_grad_{t-1} + x_t)
        e_w_t    = rho_{t-1} gamma_t lambda e_w_{t-1} + alpha_w (1 - rho_{t-1} gamma_t lambda e_w_{t-1} . x_t) x_t
        theta   += delta_t e_t + (theta_t - theta_{t-1}) . x_t (e_t - alpha rho_t x_t)
                   - alpha gamma_tp1 (1 - lambda) (w . e_grad_t) x_tp1
        w       += rho_t delta_t e_w_t - alpha_w (w . x_t) x_t

    Returns: (new state, delta_t [D]).
    """
    _check_online(state, x_t, lam, alpha, alpha_w, r_tp1, z_tp1, gamma_t, gamma_tp1, rho_t)
    v_t, v_tp1, delta = _target(state, x_t, x_tp1, r_tp1, z_tp1, gamma_tp1)
    decay = rho_t * gamma_t * lam  # [D]
    e = decay[:, None] * state.e + (rho_t * alpha * (1.0 - decay * (state.e @ x_t)))[:, None] * x_t  # [D, n]
    e_grad = rho_t[:, None] * ((gamma_t * lam)[:, None] * state.e_grad + x_t)  # [D, n]
    decay_w = state.rho_prev * gamma_t * lam  # [D]
    e_w = decay_w[:, None] * state.e_w + (alpha_w * (1.0 - decay_w * (state.e_w @ x_t)))[:, None] * x_t
    correction = alpha * gamma_tp1 * (1.0 - lam) * (state.w * e_grad).sum(axis=1)  # [D]
    theta = (
        state.theta
        + delta[:, None] * e
        + (v_t - state.v_old)[:, None] * (e - (alpha * rho_t)[:, None] * x_t)
        - correction[:, None] * x_tp1
    )
    w = state.w + (rho_t * delta)[:, None] * e_w - (alpha_w * (state.w @ x_t))[:, None] * x_t
    return OnlineState(theta, w, e, e_grad, e_w, v_tp1, rho_t, state.followon), delta


def etd_update(
    state: OnlineState, lam: np.ndarray, alpha: np.ndarray, x_t: np.ndarray, x_tp1: np.ndarray,
    r_tp1: np.ndarray, z_tp1: np.ndarray, gamma_t: np.ndarray, gamma_tp1: np.ndarray, rho_t: np.ndarray,
) -> tuple[OnlineState, np.ndarray]:  # fmt: skip
    """Emphatic TD(lambda) (Sutton, Mahmood & White 2016, JMLR 17(73)), interest 1 in every state:
        F_t = rho_{t-1} gamma_t F_{t-1} + 1,  M_t = lambda + (1 - lambda) F_t,
        e_t = rho_t (gamma_t lambda e_{t-1} + M_t x_t),  theta += alpha delta_t e_t.

    Returns: (new state, delta_t [D]).
    """
    _check_online(state, x_t, lam, alpha, r_tp1, z_tp1, gamma_t, gamma_tp1, rho_t)
    _, _, delta = _target(state, x_t, x_tp1, r_tp1, z_tp1, gamma_tp1)
    followon = state.rho_prev * gamma_t * state.followon + 1.0  # [D]
    emphasis = lam + (1.0 - lam) * followon  # [D]
    e = rho_t[:, None] * ((gamma_t * lam)[:, None] * state.e + emphasis[:, None] * x_t)  # [D, n]
    theta = state.theta + (alpha * delta)[:, None] * e
    return state._replace(theta=theta, e=e, rho_prev=rho_t, followon=followon), delta


def adaptive_td_update(
    state: OnlineState, lam: np.ndarray, autostep: np.ndarray, meta: np.ndarray, tau: float, x_t: np.ndarray,
    x_tp1: np.ndarray, r_tp1: np.ndarray, z_tp1: np.ndarray, gamma_t: np.ndarray, gamma_tp1: np.ndarray,
    rho_t: np.ndarray,
) -> tuple[OnlineState, np.ndarray]:  # fmt: skip
    """TD(lambda) with per-weight step sizes (state.e_w) adapted online: TIDBD(lambda) (Kearney, Veeriah,
    Travnik, Pilarski & Sutton 2019) where autostep is 0, Autostep (Mahmood, Sutton, Degris & Pilarski
    2012) in its TD form (AutoTIDBD, Kearney et al. 2019) where autostep is 1; see
    `reference.adaptive_td_step` for the equations. h lives in state.w, autostep's v in state.e_grad.

    Args: autostep [D] 1.0 or 0.0; meta [D] mu (autostep) or theta (tidbd); tau autostep's time scale.
    Returns: (new state, delta_t [D]).
    """
    _check_online(state, x_t, lam, autostep, meta, r_tp1, z_tp1, gamma_t, gamma_tp1, rho_t)
    _, _, delta = _target(state, x_t, x_tp1, r_tp1, z_tp1, gamma_tp1)
    e = rho_t[:, None] * (x_t + (gamma_t * lam)[:, None] * state.e)  # [D, n]
    h, v, alphas = state.w, state.e_grad, state.e_w
    sample = delta[:, None] * x_t * h  # [D, n]
    auto = autostep[:, None] > 0.0
    v = np.where(auto, np.maximum(np.abs(sample), v + alphas * x_t * e * (np.abs(sample) - v) / tau), v)
    ratio = np.where(auto, np.divide(sample, v, out=np.zeros_like(v), where=v != 0.0), sample)
    alphas = alphas * np.exp(meta[:, None] * ratio)
    effective = (alphas * e * (x_t - gamma_tp1[:, None] * x_tp1)).sum(axis=1)  # [D]
    alphas = alphas / np.where(autostep > 0.0, np.maximum(effective, 1.0), 1.0)[:, None]
    theta = state.theta + alphas * delta[:, None] * e
    h = h * np.maximum(1.0 - alphas * x_t * e, 0.0) + alphas * delta[:, None] * e
    return state._replace(theta=theta, w=h, e=e, e_grad=v, e_w=alphas, rho_prev=rho_t), delta
