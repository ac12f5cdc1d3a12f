"""Compiled kernels (numba) of the learners that need less tuning: one block step each, in the one engine.

`fast.py` runs these blocks right after `scale_fast._step` has run the group's GQ / GTD / TD blocks
(`_step` skips every block whose learner code is at least `TOTD`). The equations are those of
`learners.py` (readable) and `reference.py` (the oracle):

* true online TD(lambda) (`TOTD`): the dutch trace depends on alpha, so demons share a trace only when
  they share target policy, continuation and alpha (`horde.py` adds alpha to the trace key). Per demon it
  keeps v_old = theta_{t-1} . x_t.
* true online GTD(lambda) (`TOGTD`): three traces per class (the dutch trace of theta in the block's
  trace columns, the correction's accumulating trace and w's dutch trace in `OnlineArrays.trace2`); the
  second and third are kept dense over the block's rows (no support, no cut), so a TOGTD block costs
  O(rows x demons) a step: fine at thesis scale, slow at Horde scale (README "Learners and step sizes").
* emphatic TD(lambda) (`ETD`): the followon trace F and emphasis M are the same for a whole class (interest
  1 everywhere), so the trace is shared as TD's is; F and rho_{t-1} are kept per class.
* TD(lambda) with per-weight step sizes, `TIDBD` and `AUTOSTEP`: the accumulating trace is shared as TD's;
  each demon has its own step size per weight (`step_a`, times a per-demon scale `ascale`, so that
  Autostep's division of every step size by M costs O(1)), its own h (kept in the block's w, which TD
  leaves unused) and, for Autostep, its normaliser v (`step_v`).

A demon whose alpha is 0 (frozen: diverged, or not learning in a test run) stays exactly as it is.

Why one module of about 520 lines: the kernels of the four learners share the trace walk, the column
split and the unsigned offsets, and numba inlines and specialises calls best within one module.

As `scale_fast._step`, a step is split into what is shared (each class's trace, merged and cut once per
step: nothing per demon) and `_columns`, every demon's numbers over its own columns of the feature-major
weights, which a block of at least `PARALLEL_MIN` demons learns on the run's threads, a run of columns
each (`_columns_parallel`), to the same bits whatever the count. What each step costs per demon:

* true online TD / ETD: one walk over the rows of the trace's support, x_t and x_tp1 (theta read and
  written once per row, the values at s_{t+1} summed from each row as it moves): the support's rows, as
  TD, plus the rows of x_t that the cut dropped.
* Autostep / TIDBD: the meta step touches the rows of x_t only (phi_i = 0 elsewhere: the papers' update
  leaves alpha_i and v_i of other weights as they are), the effective step size reads the step sizes at
  x_t and x_tp1, and theta and h move on the support's rows (every weight with a nonzero trace, as the
  papers' updates). Per support row that is three numbers per demon (step size, theta, h) where TD moves
  one, and on x_t five (v and the step size written); the meta step's exp and division make that pass
  compute-bound.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit, prange

from horde.core.scale import LEARNER_CODES
from horde.core.scale_fast import (
    ALIGN,
    B_COFF,
    B_HI,
    B_LEARNER,
    B_LO,
    B_NCLS,
    B_ROWS,
    B_TOFF,
    B_VOFF,
    B_WOFF,
    PARALLEL_MIN,
    _at,
)

TOTD = LEARNER_CODES["true_online_td"]
TOGTD = LEARNER_CODES["true_online_gtd"]
ETD = LEARNER_CODES["etd"]
TIDBD = LEARNER_CODES["td+tidbd"]
AUTOSTEP = LEARNER_CODES["td+autostep"]
SMALL_EXP = 1.0 / 16  # Autostep's meta steps with mu at most this use _exp_small (|argument| <= mu)
SCALE_FLOOR = 1e-150  # a demon's lazily kept step-size scale is folded back into its step sizes below this


class OnlineArrays(NamedTuple):
    """The state of these learners beyond the engine's weights and traces (slots and classes global)."""

    v_old: np.ndarray  # [D] true online: theta_{t-1} . x_t
    cls_alpha: np.ndarray  # [C] the alpha of a true online class's dutch trace
    cls_beta: np.ndarray  # [C] TOGTD: alpha_w of the class's w trace
    cls_f: np.ndarray  # [C] ETD's followon trace
    cls_rho_prev: np.ndarray  # [C] rho_{t-1}
    trace2: np.ndarray  # TOGTD: per block [2, rows, C_b] at 2 * B_VOFF: e_grad, then e_w
    step_a: np.ndarray  # per-weight step sizes, as theta (before the scale)
    step_v: np.ndarray  # Autostep's normaliser v, as theta
    ascale: np.ndarray  # [D] the scale of each demon's step sizes
    meta: np.ndarray  # [D] mu (Autostep) or theta (TIDBD)
    tau: np.ndarray  # [1] Autostep's tau
    scratch: np.ndarray  # [8, max(C_b, Db)]
    bounds: np.ndarray  # [max(C_b) + 1] int: the first demon of each class of a block, then Db


@njit(cache=True)
def _trace_at(trace, voff, ncls, rows, c):
    """Sum of class c's trace over the given rows."""
    total = 0.0
    for j in range(rows.shape[0]):
        total += trace[voff + rows[j] * ncls + c]
    return total


@njit(cache=True)
def _merge_trace(trace, support, toff, voff, ncls, nnz_b, x_t, decay, add, cut, rows):
    """e <- decay e, plus add on the rows of x_t, per class, then the cut; returns the rows left (sorted,
    in rows[:kept]) and writes them as the block's support."""
    k = x_t.shape[0]
    i_old = 0
    j_new = 0
    kept = 0
    while i_old < nnz_b or j_new < k:
        if j_new >= k or (i_old < nnz_b and support[toff + i_old] < x_t[j_new]):
            row = support[toff + i_old]
            on_x = False
            i_old += 1
        else:
            row = x_t[j_new]
            on_x = True
            if i_old < nnz_b and support[toff + i_old] == row:
                i_old += 1
            j_new += 1
        times = 1.0  # x_t's value on the row: an index listed again (a table's repeat) is a feature of value 2
        while on_x and j_new < k and x_t[j_new] == row:
            j_new += 1
            times += 1.0
        left = False
        for c in range(ncls):
            v = trace[voff + row * ncls + c] * decay[c]
            if on_x:
                v += add[c] * times
            v = v if abs(v) >= cut else 0.0
            trace[voff + row * ncls + c] = v
            left = left or v != 0.0
        if left:
            rows[kept] = row
            kept += 1
    for s in range(kept):
        support[toff + s] = rows[s]
    return kept


@njit(cache=True)
def online_step(bi, b, lam_b, alpha, alpha_w, dcls, cut, theta, w, trace, support, rows, nnz, x_t, x_tp1, r, z,
                gamma_tp1, rho_t, gamma, q, pred, delta, touched, values, o, threads=1):  # fmt: skip
    """One transition for block b (a learner of this module), in place: the learners.py equations.

    `values[0, :Db]` must hold the block's values at s_{t+1} under the weights before this step
    (`scale_fast._read_values`); on return it holds them after, and q, pred are set for s_{t+1}.

    The traces (nothing per demon) and the TD errors first, then `_columns` over the block's demons,
    which touches only their columns: with `threads` > 1 and at least `PARALLEL_MIN` demons, the demons
    are split into runs of columns learned by that many threads (`_columns_parallel`), each column by the
    same operations in the same order as on one thread, so that the numbers do not depend on the count.
    """
    code = bi[b, B_LEARNER]
    lo, hi, woff, toff, voff = bi[b, B_LO], bi[b, B_HI], bi[b, B_WOFF], bi[b, B_TOFF], bi[b, B_VOFF]
    ncls, coff, nrows = bi[b, B_NCLS], bi[b, B_COFF], bi[b, B_ROWS]
    db = hi - lo
    decay, add, coef, fix = o.scratch[0], o.scratch[1], o.scratch[2], o.scratch[3]

    # Each class's new trace: decay gamma_t lambda rho_t, and what x_t adds.
    for c in range(ncls):
        g_t, rho = gamma[coff + c], rho_t[coff + c]
        decay[c] = g_t * lam_b * rho
        if code in (TOTD, TOGTD):  # dutch: rho alpha (1 - rho gamma_t lambda e . x_t) on x_t
            add[c] = rho * o.cls_alpha[coff + c] * (1.0 - decay[c] * _trace_at(trace, voff, ncls, x_t, c))
        elif code == ETD:  # rho M_t, with F_t = rho_{t-1} gamma_t F_{t-1} + 1 and M_t = lambda + (1 - lambda) F_t
            f = o.cls_rho_prev[coff + c] * g_t * o.cls_f[coff + c] + 1.0
            o.cls_f[coff + c] = f
            add[c] = rho * (lam_b + (1.0 - lam_b) * f)
        else:
            add[c] = rho
    if code == TOGTD:
        _togtd_traces(o, voff, nrows, ncls, coff, lam_b, x_t, gamma, rho_t)

    # The TD error of each demon, before any weight moves; the first demon of each class (bounds).
    bounds = o.bounds
    bounds[0] = 0
    for i in range(db):
        d = lo + i
        bounds[dcls[d] - coff + 1] = i + 1  # the demons of a class are consecutive, classes in order
        g1 = gamma_tp1[dcls[d]]
        v_next = values[0, i]
        dl = r[d] + (1.0 - g1) * z[d] + g1 * v_next - q[d, 0]
        delta[d] = dl
        coef[i] = 0.0
        fix[i] = 0.0
        if alpha[d] == 0.0:  # frozen
            continue
        if code in (TOTD, TOGTD):
            change = q[d, 0] - o.v_old[d]  # (theta_t - theta_{t-1}) . x_t
            coef[i] = dl + change
            fix[i] = o.cls_alpha[dcls[d]] * rho_t[dcls[d]] * change
        elif code == ETD:
            coef[i] = alpha[d] * dl
        else:
            coef[i] = dl
        o.v_old[d] = v_next

    if code == TOGTD:  # the correction and w's update read w before it moves; theta's pass follows
        _togtd_weights(o, theta, w, woff, voff, nrows, ncls, coff, lo, db, dcls, alpha, alpha_w, lam_b, x_t, x_tp1,
                       gamma_tp1, rho_t, delta)  # fmt: skip

    kept = _merge_trace(trace, support, toff, voff, ncls, nnz[b], x_t, decay, add, cut, rows)
    nnz[b] = kept
    touched[b] = kept

    small = True  # every meta step size of the block within _exp_small's range (one choice for the block)
    if code in (TIDBD, AUTOSTEP):
        rate, dlv = o.scratch[5], o.scratch[6]
        for i in range(db):
            d = lo + i
            small = small and o.meta[d] <= SMALL_EXP
            live = 1.0 if alpha[d] != 0.0 else 0.0
            rate[i] = o.ascale[d] * live
            dlv[i] = delta[d] * live if live > 0.0 else 0.0

    if threads > 1 and db >= PARALLEL_MIN:
        _columns_parallel(threads, code, small, lo, db, woff, voff, ncls, coff, nrows, kept, theta, w, trace, rows,
                          x_t, x_tp1, gamma_tp1, alpha, q, pred, values, bounds, o.scratch, o.step_a, o.step_v,
                          o.ascale, o.meta, o.tau[0])  # fmt: skip
    else:
        _columns(code, small, 0, db, lo, db, woff, voff, ncls, coff, nrows, kept, theta, w, trace, rows, x_t, x_tp1,
                 gamma_tp1, alpha, q, pred, values, bounds, o.scratch, o.step_a, o.step_v, o.ascale, o.meta,
                 o.tau[0])  # fmt: skip
    for c in range(ncls):
        gamma[coff + c] = gamma_tp1[coff + c]
        o.cls_rho_prev[coff + c] = rho_t[coff + c]


@njit(cache=True, parallel=True)
def _columns_parallel(threads, code, small, lo, db, woff, voff, ncls, coff, nrows, kept, theta, w, trace, rows, x_t,
                      x_tp1, gamma_tp1, alpha, q, pred, values, bounds, scratch, step_a, step_v, ascale, meta,
                      tau):  # fmt: skip
    """`_columns` of the block on `threads` threads, each over one run of its demons (runs start at
    multiples of ALIGN numbers, a cache line, within a row)."""
    runs = min(threads, (db + ALIGN - 1) // ALIGN)
    width = ((db + runs - 1) // runs + ALIGN - 1) // ALIGN * ALIGN
    for t in prange(runs):
        i0 = min(t * width, db)
        i1 = min(i0 + width, db)
        _columns(code, small, i0, i1, lo, db, woff, voff, ncls, coff, nrows, kept, theta, w, trace, rows, x_t, x_tp1,
                 gamma_tp1, alpha, q, pred, values, bounds, scratch, step_a, step_v, ascale, meta, tau)  # fmt: skip


@njit(cache=True)
def _next_row(rows, kept, s, x, j):
    """The smaller of rows[s] (s < kept) and x[j] (j < len(x)), or -1 when both are exhausted."""
    if s < kept:
        if j < x.shape[0] and x[j] < rows[s]:
            return x[j]
        return rows[s]
    return x[j] if j < x.shape[0] else -1


@njit(cache=True)
def _columns(code, small, i0, i1, lo, db, woff, voff, ncls, coff, nrows, kept, theta, w, trace, rows, x_t, x_tp1,
             gamma_tp1, alpha, q, pred, values, bounds, scratch, step_a, step_v, ascale, meta, tau):  # fmt: skip
    """The block's demons i0 <= i < i1 learn the transition, after the traces have moved: their columns of
    the weights (and of the adaptive modes' step sizes, h and v) and of the per-demon scratch rows only.

    One walk over the rows of the new support, x_t and x_tp1 in increasing order (all three sorted): each
    weight row is read and written once, and the new values at s_{t+1} are summed from it right after
    it has moved (in x_tp1's order, as a separate pass would). Within a row, class by class, each class's
    demons in one contiguous run, offsets unsigned (`_at`) so that the runs load contiguous vectors.
    """
    acc = values[0]
    for i in range(i0, i1):
        acc[i] = 0.0
    if code in (TIDBD, AUTOSTEP):
        _adaptive_columns(code == AUTOSTEP, small, i0, i1, lo, db, woff, voff, ncls, coff, nrows, kept, theta, w, trace,
                          rows, x_t, x_tp1, gamma_tp1, alpha, bounds, scratch, step_a, step_v, ascale, meta, tau,
                          acc)  # fmt: skip
    else:
        _dutch_columns(code != ETD, i0, i1, db, woff, voff, ncls, kept, theta, trace, rows, x_t, x_tp1, bounds,
                       scratch[2], scratch[3], acc)  # fmt: skip
    for i in range(i0, i1):
        q[lo + i, 0] = acc[i]
        pred[lo + i] = acc[i]


@njit(cache=True)
def _dutch_columns(dutch, i0, i1, db, woff, voff, ncls, kept, theta, trace, rows, x_t, x_tp1, bounds, coef, fix, acc):
    """theta += coef e over the support (true online: and -= fix on the rows of x_t; ETD: coef = alpha
    delta), then acc = the new values at x_tp1, for columns i0 <= i < i1."""
    s = 0
    j = 0
    m = 0
    while True:
        row = _next_row(rows, kept, s, x_t, j)
        if m < x_tp1.shape[0] and (row < 0 or x_tp1[m] < row):
            row = x_tp1[m]
        if row < 0:
            break
        in_support = s < kept and rows[s] == row
        s += 1 if in_support else 0
        on_x = 0.0  # x_t's and x_tp1's values on the row: how often each lists it (a table's repeat: 2)
        while j < x_t.shape[0] and x_t[j] == row:
            j += 1
            on_x += 1.0
        on_next = 0.0
        while m < x_tp1.shape[0] and x_tp1[m] == row:
            m += 1
            on_next += 1.0
        base = _at(woff + row * db)
        if in_support:
            tr = voff + row * ncls
            for c in range(ncls):
                c0 = max(bounds[c], i0)
                c1 = min(bounds[c + 1], i1)
                e = trace[tr + c]
                if dutch and on_x == 1.0:
                    for i in range(c0, c1):
                        u = _at(i)
                        t = theta[base + u] + coef[u] * e
                        theta[base + u] = t - fix[u]
                elif dutch and on_x > 0.0:
                    for i in range(c0, c1):
                        u = _at(i)
                        t = theta[base + u] + coef[u] * e
                        theta[base + u] = t - on_x * fix[u]
                else:
                    for i in range(c0, c1):
                        u = _at(i)
                        theta[base + u] += coef[u] * e
        elif dutch and on_x > 0.0:  # a row of x_t whose trace was cut
            for i in range(i0, i1):
                u = _at(i)
                theta[base + u] -= on_x * fix[u]
        if on_next == 1.0:
            for i in range(i0, i1):
                u = _at(i)
                acc[u] += theta[base + u]
        elif on_next > 0.0:
            for i in range(i0, i1):
                u = _at(i)
                acc[u] += on_next * theta[base + u]


@njit(cache=True)
def _adaptive_columns(autostep, small, i0, i1, lo, db, woff, voff, ncls, coff, nrows, kept, theta, h, trace, rows, x_t,
                      x_tp1, gamma_tp1, alpha, bounds, scratch, a, v, scale, meta, tau, acc):  # fmt: skip
    """TIDBD / Autostep for TD(lambda) (reference.adaptive_td_step) for columns i0 <= i < i1; h lives in w.

    Each class's demons in one contiguous, branch-free run (feature-major, as the other kernels): a
    frozen demon enters with rate 0 and delta 0, which leaves its weights, h, v and step sizes as they
    are. Three passes, each over few rows: the meta step on the rows of x_t (with the effective step
    size's sum there), the effective step size's part at x_tp1, then the update over the support fused
    with reading the new values at x_tp1. Per trace row this reads and writes three numbers per demon
    (step size, theta, h) where TD moves one.
    """
    rate, dlv, effective = scratch[5], scratch[6], scratch[7]
    inv_tau = 1.0 / tau
    for i in range(i0, i1):
        effective[i] = 0.0
    # The meta step on the rows of x_t (where phi_i = 1): alpha_i *= exp(meta delta h_i [/ v_i]); Autostep
    # adds alpha_i e_i to the effective step size there (alpha_i of this row moved only by this row's step).
    for j in range(x_t.shape[0]):
        base = _at(woff + x_t[j] * db)
        tr = voff + x_t[j] * ncls
        for c in range(ncls):
            c0 = max(bounds[c], i0)
            c1 = min(bounds[c + 1], i1)
            e = trace[tr + c]
            if not autostep:
                for i in range(c0, c1):
                    u = _at(i)
                    at = base + u
                    a[at] *= math.exp(meta[_at(lo + i)] * dlv[u] * h[at])
                continue
            if small:  # v_i, then the argument of exp: |x| <= mu as |sample| <= v
                for i in range(c0, c1):
                    u = _at(i)
                    at = base + u
                    sample = dlv[u] * h[at]
                    size = abs(sample)
                    vi = max(size, v[at] + a[at] * rate[u] * e * (size - v[at]) * inv_tau)
                    v[at] = vi
                    a[at] *= _exp_small(meta[_at(lo + i)] * (sample / vi if vi > 0.0 else 0.0))
                    effective[u] += a[at] * e
            else:
                for i in range(c0, c1):
                    u = _at(i)
                    at = base + u
                    sample = dlv[u] * h[at]
                    size = abs(sample)
                    vi = max(size, v[at] + a[at] * rate[u] * e * (size - v[at]) * inv_tau)
                    v[at] = vi
                    a[at] *= math.exp(meta[_at(lo + i)] * (sample / vi if vi > 0.0 else 0.0))
                    effective[u] += a[at] * e
    if autostep:  # every step size divided by M = max(1, the effective step size alpha . e (x_t - gamma x_tp1))
        for j in range(x_tp1.shape[0]):
            base = _at(woff + x_tp1[j] * db)
            for c in range(ncls):
                e = trace[voff + x_tp1[j] * ncls + c]
                if e == 0.0:
                    continue
                c0 = max(bounds[c], i0)
                c1 = min(bounds[c + 1], i1)
                for i in range(c0, c1):
                    u = _at(i)
                    effective[u] -= gamma_tp1[coff + c] * a[base + u] * e
        for i in range(i0, i1):
            m = effective[i] * rate[i]
            if m > 1.0:
                scale[lo + i] /= m
                rate[i] /= m
    for i in range(i0, i1):
        if scale[lo + i] < SCALE_FLOOR:
            _fold_scale(a, scale, woff, db, i, lo + i, woff + nrows * db)
            rate[i] = 1.0 if alpha[lo + i] != 0.0 else 0.0
    # theta += alpha delta e; h = h [1 - alpha phi e]^+ + alpha delta e, over the trace's rows; then the
    # new values at x_tp1 from each row right after it moved.
    s = 0
    j = 0
    m = 0
    while True:
        row = _next_row(rows, kept, s, x_tp1, m)
        if row < 0:
            break
        in_support = s < kept and rows[s] == row
        on_next = m < x_tp1.shape[0] and x_tp1[m] == row
        s += 1 if in_support else 0
        m += 1 if on_next else 0
        base = _at(woff + row * db)
        if in_support:
            while j < x_t.shape[0] and x_t[j] < row:
                j += 1
            on_x = j < x_t.shape[0] and x_t[j] == row
            tr = voff + row * ncls
            for c in range(ncls):
                e = trace[tr + c]
                if e == 0.0:
                    continue
                c0 = max(bounds[c], i0)
                c1 = min(bounds[c + 1], i1)
                if on_x:
                    for i in range(c0, c1):
                        u = _at(i)
                        at = base + u
                        step = a[at] * rate[u] * e
                        change = step * dlv[u]
                        theta[at] += change
                        h[at] = h[at] * max(1.0 - step, 0.0) + change
                else:
                    for i in range(c0, c1):
                        u = _at(i)
                        at = base + u
                        change = a[at] * rate[u] * e * dlv[u]
                        theta[at] += change
                        h[at] += change
        if on_next:
            for i in range(i0, i1):
                u = _at(i)
                acc[u] += theta[base + u]


@njit(cache=True)
def _togtd_traces(o, voff, nrows, ncls, coff, lam_b, x_t, gamma, rho_t):
    """TOGTD's e_grad = rho (gamma_t lambda e_grad + x_t) and e_w = rho_{t-1} gamma_t lambda e_w +
    beta (1 - rho_{t-1} gamma_t lambda e_w . x_t) x_t, per class, dense over the block's rows."""
    grad = 2 * voff
    wtr = 2 * voff + nrows * ncls
    for c in range(ncls):
        g_t, rho = gamma[coff + c], rho_t[coff + c]
        decay_w = o.cls_rho_prev[coff + c] * g_t * lam_b
        add_w = o.cls_beta[coff + c] * (1.0 - decay_w * _trace_at(o.trace2, wtr, ncls, x_t, c))
        for row in range(nrows):
            o.trace2[grad + row * ncls + c] *= rho * g_t * lam_b
            o.trace2[wtr + row * ncls + c] *= decay_w
        for j in range(x_t.shape[0]):
            o.trace2[grad + x_t[j] * ncls + c] += rho
            o.trace2[wtr + x_t[j] * ncls + c] += add_w


@njit(cache=True)
def _togtd_weights(o, theta, w, woff, voff, nrows, ncls, coff, lo, db, dcls, alpha, alpha_w, lam_b, x_t, x_tp1,
                   gamma_tp1, rho_t, delta):  # fmt: skip
    """TOGTD: theta -= alpha gamma_tp1 (1 - lambda) (w . e_grad) x_tp1 and w += rho delta e_w - beta (w . x_t) x_t,
    both from w before this step."""
    grad = 2 * voff
    wtr = 2 * voff + nrows * ncls
    for i in range(db):
        d = lo + i
        if alpha[d] == 0.0:
            continue
        c = dcls[d]
        col = c - coff
        w_grad = 0.0
        w_x = 0.0
        for row in range(nrows):
            w_grad += w[woff + row * db + i] * o.trace2[grad + row * ncls + col]
        for j in range(x_t.shape[0]):
            w_x += w[woff + x_t[j] * db + i]
        correction = alpha[d] * gamma_tp1[c] * (1.0 - lam_b) * w_grad
        for j in range(x_tp1.shape[0]):
            theta[woff + x_tp1[j] * db + i] -= correction
        step = rho_t[c] * delta[d]
        for row in range(nrows):
            w[woff + row * db + i] += step * o.trace2[wtr + row * ncls + col]
        for j in range(x_t.shape[0]):
            w[woff + x_t[j] * db + i] -= alpha_w[d] * w_x


@njit(cache=True, inline="always")
def _exp_small(x):
    """exp(x) for |x| <= SMALL_EXP: its Taylor polynomial of degree 9 (the remainder is below 3e-19 relative,
    far under the double's rounding), in multiply-adds that vectorize where math.exp is a call per number."""
    return 1.0 + x * (1.0 + x * (0.5 + x * (1.0 / 6 + x * (1.0 / 24 + x * (1.0 / 120 + x * (
        1.0 / 720 + x * (1.0 / 5040 + x * (1.0 / 40320 + x * (1.0 / 362880)))))))))  # fmt: skip


@njit(cache=True)
def _fold_scale(step_a, ascale, woff, db, i, d, end):
    """Multiply demon d's scale into its stored step sizes (column i of the block at woff..end), scale 1."""
    for at in range(woff + i, end, db):
        step_a[at] *= ascale[d]
    ascale[d] = 1.0


@njit(cache=True)
def online_reset(bi, reset, alpha, o):
    """An episode starts: adaptive demons that forget their weights (reset = "episode") restart their step
    sizes at alpha and their normalisers at 0, as `reference.ReferenceHorde.observe` does (fast.py's
    `_observe` zeroes their weights and h)."""
    for b in range(bi.shape[0]):
        if bi[b, B_LEARNER] < TIDBD:
            continue
        lo, hi, rows, woff = bi[b, B_LO], bi[b, B_HI], bi[b, B_ROWS], bi[b, B_WOFF]
        db = hi - lo
        for i in range(db):
            if not reset[lo + i]:
                continue
            for row in range(rows):
                o.step_a[woff + row * db + i] = alpha[lo + i]
                o.step_v[woff + row * db + i] = 0.0
            o.ascale[lo + i] = 1.0
