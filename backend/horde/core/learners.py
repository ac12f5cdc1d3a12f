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
