"""True online TD(lambda) and true online GTD(lambda): dutch traces, the forward view exactly.

True online TD(lambda) (van Hasselt, Mahmood & Sutton 2014; van Seijen et al. 2016, JMLR 17(145)) and true
online GTD(lambda) (van Hasselt, Mahmood & Sutton 2014, Algorithm 2). A dutch trace holds alpha, so the engine
shares one only between demons of one class and one alpha. Readable numpy forms below; `reference.py`
holds the oracle (`true_online_td_step`, `true_online_gtd_step`).

The compiled kernel: the dutch trace of theta is the block's trace (decayed and merged by
`engine.traces.merge`). True online GTD's second and third traces (the correction's accumulating trace and
w's dutch trace, `Online.trace2`) keep a support of their own (`Online.support2`), merged with x_t and cut as
the dutch trace is: w's trace decays by rho_{t-1}, so it outlives the others where rho_t = 0 cut them. Its w
moves in its columns in one pass over that support, which also reads the next step's w . e_grad and w . x from
the moved rows (`Online.w_read`: e_grad's recursion gives the next w . e_grad from them, less what the cut takes),
and theta's correction at x_{t+1} is paid in the walk that reads the new values there.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from horde.core.engine.layout import NO_NRT
from horde.core.engine.rows import at, td_error, walk
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
    dutch trace merges. Its w . e_grad_{t-1} and w . x_t come from the last step's w pass, or are read here where
    that pass did not read them (`_read_w`)."""
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
    if onl.w_read_ok[b] == 0:
        _read_w(b, lay, wts, onl, stp)
        onl.w_read_ok[b] = 1
    _togtd_traces(b, lay, wts, cls, onl, stp, scr)
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
def _togtd_traces(b, lay, wts, cls, onl, stp, scr):
    """True online GTD's e_grad = rho (gamma_t lambda e_grad + x_t) and e_w = rho_{t-1} gamma_t lambda e_w +
    beta (1 - rho_{t-1} gamma_t lambda e_w . x_t) x_t, per class, on their own support (`Online.support2`: e_w
    decays by rho_{t-1}, so it lives on where the dutch trace was cut by rho_t = 0), merged with x_t and cut as
    the dutch trace is. Each class's decays and additions are written in work[2], work[4], work[7] (the columns
    use those rows per demon afterwards). w . e_grad_t, into w_read[2], comes from w . e_grad_{t-1} and w . x_t
    (w_read[0] and [1]) by e_grad's recursion, less w times each entry that the cut takes, as it would have been
    (`_read_cut`)."""
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
    lo = lay.block_lo[b]
    for i in range(lay.block_hi[b] - lo):  # w . e_grad_t by the recursion; the cut's entries come off below
        c = lay.slot_class[lo + i] - coff
        onl.w_read[2, lo + i] = decay_g[c] * onl.w_read[0, lo + i] + add_g[c] * onl.w_read[1, lo + i]
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
        if cut > 0.0:
            _read_cut(b, row, trace2[g : g + ncls], on_x, decay_g, add_g, cut, value, lay, wts, onl)
        left_g = decay_classes(trace2[g : g + ncls], on_x, decay_g, add_g, cut, value)
        left_w = decay_classes(trace2[w : w + ncls], on_x, decay_w, add_w, cut, value)
        if left_g or left_w or on_x:  # x_t's rows stay a step even where both are cut: w moves there too
            rows[out] = row  # scr.rows is free until the dutch trace's merge
            out += 1
    for s in range(out):  # element by element: a slice copy may allocate (kernels run without NRT)
        support2[toff + s] = rows[s]
    onl.nnz2[b] = out


@njit(**NO_NRT)
def _read_cut(b, row, tr, on_x, decay, add, cut, value, lay, wts, onl):
    """Before `decay_classes` moves e_grad on this row: each entry the cut will take (`decay_classes`' own
    arithmetic), times w on the row for its class's demons, off w_read[2]."""
    lo, woff = lay.block_lo[b], lay.woff[b]
    db = lay.block_hi[b] - lo
    base = at(woff + row * db)
    for c in range(tr.shape[0]):
        t = tr[c] * decay[c] + add[c] * value if on_x else tr[c] * decay[c]
        if t != 0.0 and abs(t) < cut:
            for i in range(onl.bounds[c], onl.bounds[c + 1]):
                onl.w_read[2, lo + i] -= t * wts.w[base + at(i)]


@njit(**NO_NRT)
def _read_w(b, lay, wts, onl, stp):
    """w_read[0] = w . e_grad_{t-1} and w_read[1] = w . x_t for block b, before the traces move: what the last
    step's w pass would have read, summed over the same rows in the same order (e_grad's support and x_t's rows),
    so that a run goes on to the same bits whether it was restored or not. For the first step, an episode's
    start (traces cleared, weights forgotten) and weights loaded from a snapshot or carried over."""
    lo, woff, toff, voff, ncls = lay.block_lo[b], lay.woff[b], lay.toff[b], lay.voff[b], lay.ncls[b]
    db = lay.block_hi[b] - lo
    grad = 2 * voff
    w, trace2, bounds, support2, kept = wts.w, onl.trace2, onl.bounds, onl.support2, onl.nnz2[b]
    x_t, v_t = stp.x_t, stp.v_t
    read_e, read_x = onl.w_read[0, lo : lo + db], onl.w_read[1, lo : lo + db]
    for i in range(db):
        read_e[i] = 0.0
        read_x[i] = 0.0
    rows = support2[toff : toff + kept]
    s = 0
    m = 0
    while True:  # e_grad's support and x_t's rows as the w pass walks its support and x_{t+1}'s (`rows.walk`)
        row, in_support, _, value, s, _, m = walk(rows, kept, s, x_t[:0], v_t[:0], 0, x_t, v_t, m)
        if row < 0:
            break
        base = at(woff + row * db)
        if in_support:
            for c in range(ncls):
                e_grad = trace2[grad + row * ncls + c]
                for i in range(bounds[c], bounds[c + 1]):
                    read_e[i] += e_grad * w[base + at(i)]
        if value != 0.0:
            for i in range(db):
                read_x[i] += value * w[base + at(i)]


@njit(**NO_NRT, inline="always")
def _move_and_read(w, base, step, e, on_x, w_x, c0, c1, e_grad, value, read_e, read_x):
    """On the row at base, columns c0 <= i < c1: w += step[i] e - on_x w_x[i] (on_x 0: w += step[i] e), then
    read_e[i] += e_grad w and (value not 0) read_x[i] += value w, w as moved and stored (float32 rounds before it
    is read)."""
    if on_x != 0.0 and value != 0.0:
        for i in range(c0, c1):
            u = at(i)
            w[base + u] += step[u] * e - on_x * w_x[u]
            read_e[u] += e_grad * w[base + u]
            read_x[u] += value * w[base + u]
    elif on_x != 0.0:
        for i in range(c0, c1):
            u = at(i)
            w[base + u] += step[u] * e - on_x * w_x[u]
            read_e[u] += e_grad * w[base + u]
    elif value != 0.0:
        for i in range(c0, c1):
            u = at(i)
            w[base + u] += step[u] * e
            read_e[u] += e_grad * w[base + u]
            read_x[u] += value * w[base + u]
    else:
        for i in range(c0, c1):
            u = at(i)
            w[base + u] += step[u] * e
            read_e[u] += e_grad * w[base + u]


@njit(**NO_NRT, inline="always")
def _move_and_read_two(w, bases, step, e, on_x, w_x, c0, c1, e_grad, value, read_e, read_x):
    """`_move_and_read` on two rows that are both on x_t and on x_{t+1} (each tuple holds both rows' numbers, the
    first row's first): read_e and read_x are read and written once for the two, each still adding the first row's
    term and then the second's, so that the numbers are those of the rows one at a time."""
    base0, base1 = bases
    for i in range(c0, c1):
        u = at(i)
        w[base0 + u] += step[u] * e[0] - on_x[0] * w_x[u]
        w[base1 + u] += step[u] * e[1] - on_x[1] * w_x[u]
        moved0, moved1 = w[base0 + u], w[base1 + u]
        read_e[u] = read_e[u] + e_grad[0] * moved0 + e_grad[1] * moved1
        read_x[u] = read_x[u] + value[0] * moved0 + value[1] * moved1


@njit(**NO_NRT)
def _togtd_weights(b, i0, i1, lay, wts, dem, cls, onl, stp, scr):
    """True online GTD's demons i0 <= i < i1: w . e_grad_t and w . x_t (w before this step) as `_togtd_traces` left
    them from what the last step's w pass read (`Online.w_read`), so w is not read for them; the coefficient of
    theta's correction, alpha gamma_tp1 (1 - lambda) (w . e_grad), into work[2] for the walk over theta (0 where
    frozen); then one pass over e_grad's support and x_{t+1}'s rows: w += rho delta e_w - beta (w . x_t) x_t on
    the support, and from the moved rows the next step's w . e_grad_t and w . x_{t+1} (into w_read[0] and [1];
    x_{t+1}'s rows outside the support read only)."""
    lo, woff, toff, voff, nrows, ncls = lay.block_lo[b], lay.woff[b], lay.toff[b], lay.voff[b], lay.rows[b], lay.ncls[b]
    db = lay.block_hi[b] - lo
    grad = 2 * voff
    wtr = grad + nrows * ncls
    w, trace2, bounds, support2, kept = wts.w, onl.trace2, onl.bounds, onl.support2, onl.nnz2[b]
    x_t, v_t, x_tp1, v_tp1 = stp.x_t, stp.v_t, stp.x_tp1, stp.v_tp1
    w_grad, w_x, step = scr.work[2], scr.work[4], scr.work[7]
    read_e, read_x, w_e = onl.w_read[0, lo : lo + db], onl.w_read[1, lo : lo + db], onl.w_read[2, lo : lo + db]
    for i in range(i0, i1):
        w_grad[i] = w_e[i]
        w_x[i] = read_x[i]
    for i in range(i0, i1):
        d = lo + i
        c = lay.slot_class[d]
        live = dem.alpha[d] != 0.0  # a frozen demon moves nothing
        w_grad[i] = dem.alpha[d] * cls.gamma_tp1[c] * (1.0 - lay.lam[b]) * w_grad[i] if live else 0.0
        w_x[i] = dem.alpha_w[d] * w_x[i] if live else 0.0
        step[i] = cls.rho[c] * dem.delta[d] if live else 0.0
        read_e[i] = 0.0
        read_x[i] = 0.0
    rows = support2[toff : toff + kept]  # (x_t's rows are in it: `_togtd_traces` keeps them a step)
    k, k1 = x_t.shape[0], x_tp1.shape[0]
    s = 0
    j = 0
    m = 0
    while True:
        row, in_support, on_x, value, s, j, m = walk(rows, kept, s, x_t, v_t, j, x_tp1, v_tp1, m)
        if row < 0:
            break
        base = at(woff + row * db)
        if in_support:
            if on_x != 0.0 and value != 0.0 and s < kept and j < k and m < k1:
                row1 = rows[s]
                if x_tp1[m] == row1 and x_t[j] == row1 and v_tp1[m] != 0.0 and v_t[j] != 0.0:
                    bases = (base, at(woff + row1 * db))  # the next row moved and read too: the two at once
                    on_xs, values = (on_x, v_t[j]), (value, v_tp1[m])
                    for c in range(ncls):
                        c0, c1 = max(bounds[c], i0), min(bounds[c + 1], i1)
                        e_w = (trace2[wtr + row * ncls + c], trace2[wtr + row1 * ncls + c])
                        e_grad = (trace2[grad + row * ncls + c], trace2[grad + row1 * ncls + c])
                        _move_and_read_two(w, bases, step, e_w, on_xs, w_x, c0, c1, e_grad, values, read_e, read_x)
                    s += 1
                    j += 1
                    m += 1
                    continue
            for c in range(ncls):
                c0, c1 = max(bounds[c], i0), min(bounds[c + 1], i1)
                e_w, e_grad = trace2[wtr + row * ncls + c], trace2[grad + row * ncls + c]
                _move_and_read(w, base, step, e_w, on_x, w_x, c0, c1, e_grad, value, read_e, read_x)
        elif value != 0.0:  # a row of x_{t+1} outside e_grad's support: read only
            for i in range(i0, i1):
                u = at(i)
                read_x[u] += value * w[base + u]


@njit(**NO_NRT)
def episode_start(onl):
    """An episode starts: x_t is the new episode's first state, and weights may have been forgotten: the first
    step reads w afresh (true online GTD's w_read, TIDBD's largest |phi h|: `Online.w_read_ok`)."""
    onl.w_read_ok[:] = 0
