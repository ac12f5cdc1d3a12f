"""True online TD(lambda) and true online GTD(lambda): dutch traces, the forward view exactly.

True online TD(lambda) (van Hasselt, Mahmood & Sutton 2014; van Seijen et al. 2016, JMLR 17(145)) and true
online GTD(lambda) (van Hasselt, Mahmood & Sutton 2014, Algorithm 2). A dutch trace holds alpha, so the engine
shares one only between demons of one class and one alpha. Readable numpy forms below; `reference.py`
holds the oracle (`true_online_td_step`, `true_online_gtd_step`).

The compiled kernel: the dutch trace of theta is the block's trace (decayed and merged by
`engine.traces.merge`). True online GTD's second and third traces (the correction's accumulating trace and
w's dutch trace, `Online.trace2`) keep a support of their own (`Online.support2`), merged with x_t and cut as
the dutch trace is: w's trace decays by rho_{t-1}, so it outlives the others where rho_t = 0 cut them. Its w
moves in its columns over that support (two passes: w . e_grad and w . x_t read before w moves), and theta's
correction at x_{t+1} is paid in the walk that reads the new values there.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from horde.core.engine.layout import NO_NRT
from horde.core.engine.rows import at, td_error
from horde.core.engine.traces import decay_classes, merge, trace_dot
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
    alpha rho_t (theta_t - theta_{t-1}) . x_t; then its second and third traces move (`_togtd_traces`) and the
    dutch trace merges."""
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
    _togtd_traces(b, lay, cls, onl, stp, scr)
    kept, _ = merge(b, lay, wts, scr, stp.x_t, stp.v_t, 0, False)
    scr.counts[0] = kept


@njit(**NO_NRT)
def columns(code, b, i0, i1, lay, wts, dem, cls, stp, scr, onl):
    """Block b's demons i0 <= i < i1. True online TD: `td_pass.walk` pays what the last step owes (coef e_{t-1} -
    fix x_{t-1}) and reads theta_t . x_{t+1}; then the TD errors and what this step owes (`_owe`). True online
    GTD: w moves (`_togtd_weights`), then theta += coef e - fix x_t - correction x_{t+1} in one walk, which reads
    the new values."""
    if code == TOTD_CODE:
        td_pass.walk(b, i0, i1, lay, wts, stp, scr, True)
        _owe(b, i0, i1, lay, wts, dem, cls, onl, scr)
    else:
        _togtd_weights(b, i0, i1, lay, wts, dem, cls, onl, stp, scr)
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
def _togtd_traces(b, lay, cls, onl, stp, scr):
    """True online GTD's e_grad = rho (gamma_t lambda e_grad + x_t) and e_w = rho_{t-1} gamma_t lambda e_w +
    beta (1 - rho_{t-1} gamma_t lambda e_w . x_t) x_t, per class, on their own support (`Online.support2`: e_w
    decays by rho_{t-1}, so it lives on where the dutch trace was cut by rho_t = 0), merged with x_t and cut as
    the dutch trace is. Each class's decays and additions are written in work[2], work[4], work[7] (the columns
    use those rows per demon afterwards)."""
    toff, voff, nrows, ncls, coff, lam_b, cut = lay.toff[b], lay.voff[b], lay.rows[b], lay.ncls[b], lay.coff[b], \
        lay.lam[b], lay.cut  # fmt: skip
    grad = 2 * voff
    wtr = grad + nrows * ncls
    x_t, v_t, trace2, support2, rows = stp.x_t, stp.v_t, onl.trace2, onl.support2, scr.rows
    decay_g, decay_w, add_w = scr.work[2], scr.work[4], scr.work[7]
    add_g = cls.rho[coff : coff + ncls]
    for c in range(ncls):
        decay_g[c] = cls.rho[coff + c] * cls.gamma[coff + c] * lam_b
        decay_w[c] = onl.cls_rho_prev[coff + c] * cls.gamma[coff + c] * lam_b
        add_w[c] = onl.cls_beta[coff + c] * (1.0 - decay_w[c] * trace_dot(trace2, wtr, ncls, c, x_t, v_t))
    # x_t's rows by membership, not by value (`rows.walk` reads a row of value 0 as off x_t): `_togtd_weights`
    # finds every row of x_t in this support
    k = x_t.shape[0]
    old = onl.nnz2[b]
    i_old = 0
    j = 0
    out = 0
    while i_old < old or j < k:
        if j >= k or (i_old < old and support2[toff + i_old] < x_t[j]):
            row = support2[toff + i_old]
            on_x = False
            value = 0.0
            i_old += 1
        else:
            row = x_t[j]
            on_x = True
            value = v_t[j]
            if i_old < old and support2[toff + i_old] == row:
                i_old += 1
            j += 1
        g = grad + row * ncls
        w = wtr + row * ncls
        left_g = decay_classes(trace2[g : g + ncls], on_x, decay_g, add_g, cut, value)
        left_w = decay_classes(trace2[w : w + ncls], on_x, decay_w, add_w, cut, value)
        if left_g or left_w or on_x:  # x_t's rows stay a step even where both are cut: w moves there too
            rows[out] = row  # scr.rows is free until the dutch trace's merge
            out += 1
    for s in range(out):  # element by element: a slice copy may allocate (kernels run without NRT)
        support2[toff + s] = rows[s]
    onl.nnz2[b] = out


@njit(**NO_NRT)
def _togtd_weights(b, i0, i1, lay, wts, dem, cls, onl, stp, scr):
    """True online GTD's demons i0 <= i < i1: w . e_grad and w . x_t read over e_grad's support, which holds the
    rows of x_t (w before this step); then on the same rows w += rho delta e_w - beta (w . x_t) x_t; and the
    coefficient of theta's correction, alpha gamma_tp1 (1 - lambda) (w . e_grad), into work[2] for the walk over
    theta (0 where frozen)."""
    lo, woff, toff, voff, nrows, ncls = lay.block_lo[b], lay.woff[b], lay.toff[b], lay.voff[b], lay.rows[b], lay.ncls[b]
    db = lay.block_hi[b] - lo
    grad = 2 * voff
    wtr = grad + nrows * ncls
    w, trace2, bounds, support2, kept = wts.w, onl.trace2, onl.bounds, onl.support2, onl.nnz2[b]
    x_t, v_t = stp.x_t, stp.v_t
    w_grad, w_x, step = scr.work[2], scr.work[4], scr.work[7]
    for i in range(i0, i1):
        w_grad[i] = 0.0
        w_x[i] = 0.0
    j = 0
    for s in range(kept):
        row = support2[toff + s]
        base = at(woff + row * db)
        tr = grad + row * ncls
        for c in range(ncls):
            e = trace2[tr + c]
            for i in range(max(bounds[c], i0), min(bounds[c + 1], i1)):
                u = at(i)
                w_grad[u] += e * w[base + u]
        if j < x_t.shape[0] and x_t[j] == row:
            on_x = v_t[j]
            j += 1
            for i in range(i0, i1):
                u = at(i)
                w_x[u] += on_x * w[base + u]
    for i in range(i0, i1):
        d = lo + i
        c = lay.slot_class[d]
        live = dem.alpha[d] != 0.0  # a frozen demon moves nothing
        w_grad[i] = dem.alpha[d] * cls.gamma_tp1[c] * (1.0 - lay.lam[b]) * w_grad[i] if live else 0.0
        w_x[i] = dem.alpha_w[d] * w_x[i] if live else 0.0
        step[i] = cls.rho[c] * dem.delta[d] if live else 0.0
    j = 0
    for s in range(kept):
        row = support2[toff + s]
        base = at(woff + row * db)
        tr = wtr + row * ncls
        on_x = 0.0
        if j < x_t.shape[0] and x_t[j] == row:
            on_x = v_t[j]
            j += 1
        for c in range(ncls):
            e = trace2[tr + c]
            c0, c1 = max(bounds[c], i0), min(bounds[c + 1], i1)
            if on_x != 0.0:
                for i in range(c0, c1):
                    u = at(i)
                    w[base + u] += step[u] * e - on_x * w_x[u]
            else:
                for i in range(c0, c1):
                    u = at(i)
                    w[base + u] += step[u] * e
