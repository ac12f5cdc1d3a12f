"""True online TD(lambda) and true online GTD(lambda): dutch traces, the forward view exactly.

True online TD(lambda) (van Hasselt, Mahmood & Sutton 2014; van Seijen et al. 2016, JMLR 17(145)) and true
online GTD(lambda) (van Hasselt, Mahmood & Sutton 2014, Algorithm 2). A dutch trace holds alpha, so the engine
shares one only between demons of one class and one alpha. Readable numpy forms below; `reference.py`
holds the oracle (`true_online_td_step`, `true_online_gtd_step`).

The compiled kernel: the dutch trace of theta is the block's trace (decayed and merged by
`engine.traces.merge`); true online GTD's second and third traces (the correction's accumulating trace and
w's dutch trace) are kept dense over the block's rows (`Online.trace2`, no support, no cut), so a true online
GTD block costs O(rows x demons) a step: fine at thesis scale, slow at Horde scale (README "Learners and
step sizes").
"""

from __future__ import annotations

import numpy as np
from numba import njit

from horde.core.engine.layout import NO_NRT
from horde.core.engine.rows import td_error
from horde.core.engine.traces import merge, trace_dot
from horde.core.learners import td_pass
from horde.core.learners.base import Kernel, OnlineState, check_online, target
from horde.core.learners.online import class_bounds, dutch_columns, read_errors, store_values
from horde.spec.learners import LearnerInfo, register

TRUE_ONLINE_TD = register(LearnerInfo(
    name="true_online_td", text="true online TD(λ): the forward view exactly, less step-size sensitive",
    paper="van Seijen, Mahmood, Pilarski, Machado & Sutton 2016",
))  # fmt: skip
TRUE_ONLINE_GTD = register(LearnerInfo(
    name="true_online_gtd", text="true online GTD(λ): the same, with GTD's correction",
    paper="van Hasselt, Mahmood & Sutton 2014", secondary=True,
))  # fmt: skip
TOTD_CODE, TOGTD_CODE = 3, 4  # the engine's kernel codes
KERNELS = (
    Kernel(TOTD_CODE, "true_online_td", dutch=True, keeps_state=True),
    Kernel(TOGTD_CODE, "true_online_gtd", vectors=2, dutch=True, keeps_state=True),
)


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
    check_online(state, x_t, lam, alpha, r_tp1, z_tp1, gamma_t, gamma_tp1, rho_t)
    v_t, v_tp1, delta = target(state, x_t, x_tp1, r_tp1, z_tp1, gamma_tp1)
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
    check_online(state, x_t, lam, alpha, alpha_w, r_tp1, z_tp1, gamma_t, gamma_tp1, rho_t)
    v_t, v_tp1, delta = target(state, x_t, x_tp1, r_tp1, z_tp1, gamma_tp1)
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


# ----------------------------------------------------------------------------------------------
# The compiled kernel


@njit(**NO_NRT)
def prepare(code, b, lay, wts, dem, cls, onl, stp, scr):
    """Block b before its columns: each class's dutch trace will decay by gamma_t lambda rho_t and x_t add
    rho_t alpha (1 - rho_t gamma_t lambda e_{t-1} . x_t). True online TD learns in one walk (`columns`, the merge
    in `td_pass.finish`). True online GTD reads the values at s_{t+1} and the TD errors before any weight moves
    (`read_errors`), with what its weight pass takes: coef = delta + (theta_t - theta_{t-1}) . x_t and fix =
    alpha rho_t (theta_t - theta_{t-1}) . x_t; then moves its w (which reads the TD errors and w before it moves)
    and corrects theta at x_tp1, before the trace merges."""
    lo, ncls, coff, voff = lay.block_lo[b], lay.ncls[b], lay.coff[b], lay.voff[b]
    for c in range(ncls):
        rho = cls.rho[coff + c]
        scr.decay[c] = cls.gamma[coff + c] * lay.lam[b] * rho
        e_x = trace_dot(wts.trace, voff, ncls, c, stp.x_t, stp.v_t)
        scr.add[c] = rho * onl.cls_alpha[coff + c] * (1.0 - scr.decay[c] * e_x)
    if code == TOTD_CODE:
        return
    class_bounds(b, lay, onl)
    read_errors(b, lay, wts, dem, cls, onl, stp, scr)
    coef, fix, rate, dlv, v_old = scr.work[0], scr.work[1], scr.work[5], scr.work[6], scr.work[3]
    for i in range(lay.block_hi[b] - lo):
        d = lo + i
        change = dem.q[d, 0] - v_old[i]  # (theta_t - theta_{t-1}) . x_t
        live = rate[i] != 0.0
        coef[i] = dlv[i] + change if live else 0.0
        c = lay.slot_class[d]
        fix[i] = onl.cls_alpha[c] * cls.rho[c] * change if live else 0.0
    _togtd_traces(b, lay, cls, onl, stp)
    _togtd_weights(b, lay, wts, dem, cls, onl, stp)
    kept, _ = merge(b, lay, wts, scr, stp.x_t, stp.v_t, 0, False)
    scr.counts[0] = kept


@njit(**NO_NRT)
def columns(code, b, i0, i1, lay, wts, dem, cls, stp, scr, onl):
    """Block b's demons i0 <= i < i1. True online TD: `td_pass.walk` pays what the last step owes (coef e_{t-1} -
    fix x_{t-1}) and reads theta_t . x_{t+1}; then the TD errors and what this step owes (`_owe`). True online
    GTD: theta += coef e - fix x_t over the support, then the new values."""
    if code == TOTD_CODE:
        td_pass.walk(b, i0, i1, lay, wts, stp, scr, True)
        _owe(b, i0, i1, lay, wts, dem, cls, onl, scr)
    else:
        dutch_columns(b, i0, i1, lay, wts, stp, scr, onl)
        store_values(b, i0, i1, lay, dem, scr)


@njit(**NO_NRT)
def _owe(b, i0, i1, lay, wts, dem, cls, onl, scr):
    """True online TD's demons i0 <= i < i1 after the walk: the TD error from theta_t . x_{t+1} (scr.values[0]),
    and what theta owes the next walk, coef_t e_t - fix_t x_t: coef = delta_t + (theta_t - theta_{t-1}) . x_t in
    owed[0], fix = alpha rho_t (theta_t - theta_{t-1}) . x_t in owed[1] (0 for a frozen demon); v_old moves to
    theta_t . x_{t+1}."""
    lo, acc, owed = lay.block_lo[b], scr.values[0], wts.owed
    for i in range(i0, i1):
        d = lo + i
        c = lay.slot_class[d]
        v_tp1 = acc[i]
        dl = td_error(dem.r[d], dem.z[d], cls.gamma_tp1[c], v_tp1, dem.q[d, 0])
        dem.delta[d] = dl
        change = dem.q[d, 0] - onl.v_old[d]  # (theta_t - theta_{t-1}) . x_t
        live = dem.alpha[d] != 0.0  # a frozen demon owes nothing and keeps its v_old
        owed[0, d] = dl + change if live else 0.0
        owed[1, d] = onl.cls_alpha[c] * cls.rho[c] * change if live else 0.0
        if live:
            onl.v_old[d] = v_tp1


@njit(**NO_NRT)
def _togtd_traces(b, lay, cls, onl, stp):
    """True online GTD's e_grad = rho (gamma_t lambda e_grad + x_t) and e_w = rho_{t-1} gamma_t lambda e_w +
    beta (1 - rho_{t-1} gamma_t lambda e_w . x_t) x_t, per class, dense over the block's rows."""
    voff, nrows, ncls, coff, lam_b = lay.voff[b], lay.rows[b], lay.ncls[b], lay.coff[b], lay.lam[b]
    grad = 2 * voff
    wtr = 2 * voff + nrows * ncls
    x_t, v_t, trace2 = stp.x_t, stp.v_t, onl.trace2
    for c in range(ncls):
        g_t, rho = cls.gamma[coff + c], cls.rho[coff + c]
        decay_w = onl.cls_rho_prev[coff + c] * g_t * lam_b
        add_w = onl.cls_beta[coff + c] * (1.0 - decay_w * trace_dot(trace2, wtr, ncls, c, x_t, v_t))
        for row in range(nrows):
            trace2[grad + row * ncls + c] *= rho * g_t * lam_b
            trace2[wtr + row * ncls + c] *= decay_w
        for j in range(x_t.shape[0]):
            trace2[grad + x_t[j] * ncls + c] += rho * v_t[j]
            trace2[wtr + x_t[j] * ncls + c] += add_w * v_t[j]


@njit(**NO_NRT)
def _togtd_weights(b, lay, wts, dem, cls, onl, stp):
    """True online GTD: theta -= alpha gamma_tp1 (1 - lambda) (w . e_grad) x_tp1 and w += rho delta e_w -
    beta (w . x_t) x_t, both from w before this step."""
    lo, woff, voff, nrows, ncls, coff = lay.block_lo[b], lay.woff[b], lay.voff[b], lay.rows[b], lay.ncls[b], lay.coff[b]
    db = lay.block_hi[b] - lo
    grad = 2 * voff
    wtr = 2 * voff + nrows * ncls
    theta, w, trace2 = wts.theta, wts.w, onl.trace2
    x_t, v_t, x_tp1, v_tp1 = stp.x_t, stp.v_t, stp.x_tp1, stp.v_tp1
    for i in range(db):
        d = lo + i
        if dem.alpha[d] == 0.0:
            continue
        c = lay.slot_class[d]
        col = c - coff
        w_grad = 0.0
        w_x = 0.0
        for row in range(nrows):
            w_grad += w[woff + row * db + i] * trace2[grad + row * ncls + col]
        for j in range(x_t.shape[0]):
            w_x += v_t[j] * w[woff + x_t[j] * db + i]
        correction = dem.alpha[d] * cls.gamma_tp1[c] * (1.0 - lay.lam[b]) * w_grad
        for j in range(x_tp1.shape[0]):
            theta[woff + x_tp1[j] * db + i] -= correction * v_tp1[j]
        step = cls.rho[c] * dem.delta[d]
        for row in range(nrows):
            w[woff + row * db + i] += step * trace2[wtr + row * ncls + col]
        for j in range(x_t.shape[0]):
            w[woff + x_t[j] * db + i] -= dem.alpha_w[d] * w_x * v_t[j]
