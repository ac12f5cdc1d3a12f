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

Why one module of about 600 lines: the kernels of the four learners share the trace walk, the column
split and the unsigned offsets, and numba inlines and specialises calls best within one module.

As `scale_fast._step`, a step is split into what is shared (each class's trace, merged and cut once per
step: nothing per demon) and `_columns`, every demon's numbers over its own columns of the feature-major
weights, which a block of at least `PARALLEL_MIN` demons learns on the run's threads, a run of columns
each (`_columns_parallel`), to the same bits whatever the count. What each step costs per demon:

* true online TD / ETD: one walk over the rows of the trace's support, x_t and x_tp1 (theta read and
  written once per row, the values at s_{t+1} summed from each row as it moves): the support's rows, as
  TD, plus the rows of x_t that the cut dropped.
* Autostep / TIDBD: three passes over few rows. The values at x_tp1 under the weights before the step
  (read on the threads, then the TD errors: `fast.py` leaves this read to `online_step`); the meta step
  on the rows of x_t only (phi_i = 0 elsewhere: the papers' update leaves alpha_i and v_i of other weights
  as they are); theta and h on the support's rows (every weight with a nonzero trace, as the papers'
  updates), fused with reading the new values at x_tp1. Autostep's effective step size
  alpha . e (x_t - gamma x_tp1) is summed within the first two passes (on a row of x_tp1 alone in the
  first, whose step sizes do not move; on a row of x_t after its step sizes moved), not in a pass of its
  own. Per x_t row that is ten numbers per demon read or written (h, v, alpha in the meta step: v and
  alpha written; alpha, theta, h in the update: theta and h written), per other support row five, where
  TD moves two (theta) plus the read at x_tp1: about 3.5 times TD's bytes, and both are bound by memory.
  The paper's order divides every step size by M, a sum over all the rows of x_t, before theta moves;
  for a run of demons whose M provably stays 1 (an upper bound from the step sizes before the meta step,
  read in the first pass, as |the meta step's argument| <= mu) the meta step and the update go in one
  walk (`fused_columns`, the same operations in the same order: the same numbers), each row of x_t
  visited once. Autostep's exp is a polynomial when the block's meta step sizes allow (`_exp_tiny`,
  `_exp_small`), chosen once per block; `_adaptive_kernel` compiles the kernel once per kind of exp.
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
    _read_range,
    listed,
)

TOTD = LEARNER_CODES["true_online_td"]
TOGTD = LEARNER_CODES["true_online_gtd"]
ETD = LEARNER_CODES["etd"]
TIDBD = LEARNER_CODES["td+tidbd"]
AUTOSTEP = LEARNER_CODES["td+autostep"]
TINY_EXP = 0.01  # Autostep's meta steps with mu at most this use _exp_tiny (|argument| <= mu), the default mu
SMALL_EXP = 1.0 / 16  # ... with mu at most this _exp_small, above it math.exp
EXP_ANY, EXP_SMALL, EXP_TINY = 0, 1, 2  # which exp a block's meta steps take (`online_step`)
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

    On return `values[0, :Db]` holds the block's values at s_{t+1} under the new weights, and q, pred
    are set for s_{t+1}; the values there under the weights before the step (for the TD errors) are read
    here: by the threads for the adaptive modes, before the columns for the others.

    The traces (nothing per demon) first, then `_columns` over the block's demons, which touches only
    their columns: with `threads` > 1 and at least `PARALLEL_MIN` demons, the demons are split into runs
    of columns learned by that many threads (`_columns_parallel`), each column by the same operations in
    the same order as on one thread, so that the numbers do not depend on the count.
    """
    code = bi[b, B_LEARNER]
    lo, hi, woff, toff, voff = bi[b, B_LO], bi[b, B_HI], bi[b, B_WOFF], bi[b, B_TOFF], bi[b, B_VOFF]
    ncls, coff, nrows = bi[b, B_NCLS], bi[b, B_COFF], bi[b, B_ROWS]
    db = hi - lo
    decay, add = o.scratch[0], o.scratch[1]

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
    # The first demon of each class (bounds; the demons of a class are consecutive, classes in order).
    bounds = o.bounds
    bounds[0] = 0
    for i in range(db):
        bounds[dcls[lo + i] - coff + 1] = i + 1
    adaptive = code in (TIDBD, AUTOSTEP)
    if not adaptive:  # the values at s_{t+1} and the TD errors, before any weight moves (TOGTD's w pass reads them)
        _read_range(bi, b, 0, theta, x_tp1, 0, db, values)
        _errors(code, 0, db, lo, dcls, alpha, r, z, gamma_tp1, rho_t, q, values[0], delta, o)
    if code == TOGTD:  # the correction and w's update read w before it moves; theta's pass follows
        _togtd_traces(o, voff, nrows, ncls, coff, lam_b, x_t, gamma, rho_t)
        _togtd_weights(o, theta, w, woff, voff, nrows, ncls, coff, lo, db, dcls, alpha, alpha_w, lam_b, x_t, x_tp1,
                       gamma_tp1, rho_t, delta)  # fmt: skip

    kept = _merge_trace(trace, support, toff, voff, ncls, nnz[b], x_t, decay, add, cut, rows)
    nnz[b] = kept
    touched[b] = kept

    bound = 0.0  # the largest meta step size of the block: which exp its meta steps take (one kind for the block)
    for i in range(db if code == AUTOSTEP else 0):
        bound = max(bound, o.meta[lo + i])
    exp_kind = _exp_kind(bound)
    if threads > 1 and db >= PARALLEL_MIN:
        _columns_parallel(threads, code, exp_kind, lo, db, woff, voff, ncls, coff, nrows, kept, theta, w, trace, rows,
                          x_t, x_tp1, dcls, alpha, r, z, gamma_tp1, rho_t, q, pred, delta, values, o)  # fmt: skip
    else:
        _columns(code, exp_kind, 0, db, lo, db, woff, voff, ncls, coff, nrows, kept, theta, w, trace, rows, x_t, x_tp1,
                 dcls, alpha, r, z, gamma_tp1, rho_t, q, pred, delta, values, o)  # fmt: skip
    for c in range(ncls):
        gamma[coff + c] = gamma_tp1[coff + c]
        o.cls_rho_prev[coff + c] = rho_t[coff + c]


@njit(cache=True)
def _exp_kind(bound):
    """Which exp Autostep's meta steps take when no meta step size of the block is above `bound` (|the
    argument| <= mu, as |delta phi h| <= v)."""
    return EXP_TINY if bound <= TINY_EXP else (EXP_SMALL if bound <= SMALL_EXP else EXP_ANY)


@njit(cache=True)
def _errors(code, i0, i1, lo, dcls, alpha, r, z, gamma_tp1, rho_t, q, v_next, delta, o):
    """The TD errors of the block's demons i0 <= i < i1 from their values v_next[i] at s_{t+1} under the
    weights before the step, and what each learner's weight pass takes of them (scratch rows 2, 3, 5, 6)."""
    coef, fix, rate, dlv = o.scratch[2], o.scratch[3], o.scratch[5], o.scratch[6]
    for i in range(i0, i1):
        d = lo + i
        g1 = gamma_tp1[dcls[d]]
        dl = r[d] + (1.0 - g1) * z[d] + g1 * v_next[i] - q[d, 0]
        delta[d] = dl
        coef[i] = 0.0
        fix[i] = 0.0
        live = alpha[d] != 0.0
        rate[i] = o.ascale[d] if live else 0.0  # adaptive modes: a frozen demon moves nothing (rate and delta 0)
        dlv[i] = dl if live else 0.0
        if not live:  # frozen
            continue
        if code in (TOTD, TOGTD):
            change = q[d, 0] - o.v_old[d]  # (theta_t - theta_{t-1}) . x_t
            coef[i] = dl + change
            fix[i] = o.cls_alpha[dcls[d]] * rho_t[dcls[d]] * change
        elif code == ETD:
            coef[i] = alpha[d] * dl
        else:
            coef[i] = dl
        o.v_old[d] = v_next[i]


@njit(cache=True, parallel=True)
def _columns_parallel(threads, code, exp_kind, lo, db, woff, voff, ncls, coff, nrows, kept, theta, w, trace, rows, x_t,
                      x_tp1, dcls, alpha, r, z, gamma_tp1, rho_t, q, pred, delta, values, o):  # fmt: skip
    """`_columns` of the block on `threads` threads, each over one run of its demons (runs start at
    multiples of ALIGN numbers, a cache line, within a row)."""
    runs = min(threads, (db + ALIGN - 1) // ALIGN)
    width = ((db + runs - 1) // runs + ALIGN - 1) // ALIGN * ALIGN
    for t in prange(runs):
        i0 = min(t * width, db)
        i1 = min(i0 + width, db)
        _columns(code, exp_kind, i0, i1, lo, db, woff, voff, ncls, coff, nrows, kept, theta, w, trace, rows, x_t, x_tp1,
                 dcls, alpha, r, z, gamma_tp1, rho_t, q, pred, delta, values, o)  # fmt: skip


@njit(cache=True)
def _next_row(rows, kept, s, x, j):
    """The smaller of rows[s] (s < kept) and x[j] (j < len(x)), or -1 when both are exhausted."""
    if s < kept:
        if j < x.shape[0] and x[j] < rows[s]:
            return x[j]
        return rows[s]
    return x[j] if j < x.shape[0] else -1


@njit(cache=True, inline="always")
def _walk(rows, kept, s, x_t, j, x_tp1, m):
    """The next row of a walk over the support (rows[:kept]), x_t and x_tp1, all sorted, from positions s, j
    and m: (the row, or -1 at the end; whether it is in the support; x_t's and x_tp1's values on it, how
    often each lists it: 0, 1, or 2 for a table's repeat; the three positions past it)."""
    row = _next_row(rows, kept, s, x_t, j)
    if m < x_tp1.shape[0] and (row < 0 or x_tp1[m] < row):
        row = x_tp1[m]
    in_support = s < kept and rows[s] == row
    on_x, j = listed(x_t, j, row)
    on_next, m = listed(x_tp1, m, row)
    return row, in_support, on_x, on_next, s + in_support, j, m


@njit(cache=True)
def _columns(code, exp_kind, i0, i1, lo, db, woff, voff, ncls, coff, nrows, kept, theta, w, trace, rows, x_t, x_tp1,
             dcls, alpha, r, z, gamma_tp1, rho_t, q, pred, delta, values, o):  # fmt: skip
    """The block's demons i0 <= i < i1 learn the transition, after the traces have moved: their columns of
    the weights (and of the adaptive modes' step sizes, h and v) and of the per-demon scratch rows only.

    One walk over the rows of the new support, x_t and x_tp1 in increasing order (all three sorted): each
    weight row is read and written once, and the new values at s_{t+1} are summed from it right after
    it has moved (in x_tp1's order, as a separate pass would). Within a row, class by class, each class's
    demons in one contiguous run, offsets unsigned (`_at`) so that the runs load contiguous vectors.
    """
    acc = values[0]
    if code in (TIDBD, AUTOSTEP):
        args = (code, i0, i1, lo, db, woff, voff, ncls, coff, nrows, kept, theta, w, trace, rows, x_t, x_tp1, dcls,
                alpha, r, z, gamma_tp1, rho_t, q, delta, o, acc)  # fmt: skip
        if exp_kind == EXP_TINY:
            _adaptive_tiny(*args)
        elif exp_kind == EXP_SMALL:
            _adaptive_small(*args)
        else:
            _adaptive_any(*args)
    else:
        for i in range(i0, i1):
            acc[i] = 0.0
        _dutch_columns(code != ETD, i0, i1, db, woff, voff, ncls, kept, theta, trace, rows, x_t, x_tp1, o.bounds,
                       o.scratch[2], o.scratch[3], acc)  # fmt: skip
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
        row, in_support, on_x, on_next, s, j, m = _walk(rows, kept, s, x_t, j, x_tp1, m)
        if row < 0:
            break
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
            _add_row(i0, i1, base, theta, acc)
        elif on_next > 0.0:
            for i in range(i0, i1):
                u = _at(i)
                acc[u] += on_next * theta[base + u]


def _adaptive_kernel(exp):
    """TIDBD / Autostep for TD(lambda) (reference.adaptive_td_step), compiled once per kind of exp for
    Autostep's meta step (`exp`: `_exp_tiny`, `_exp_small` or `_exp`; chosen once per block by `_columns`),
    so that the source is written once and each hot loop has one kind of exp.

    Why about 180 lines: the factory is the compiled kernels themselves (the meta step, the fused walk and
    the two-pass columns, each short): they are closures over `exp`, so that numba binds the exp when it
    compiles them, and closures must be written inside the function that makes them."""

    @njit(inline="always")
    def meta_step(at, u, mu, e, inv_tau, a, v, h, rate, dlv):
        """Autostep's meta step of one weight from h_i as it was: v_i, then the argument of exp (|sample| <=
        v_i), then alpha_i; returns the new alpha_i."""
        sample = dlv[u] * h[at]
        size = abs(sample)
        vi = max(size, v[at] + a[at] * rate[u] * e * (size - v[at]) * inv_tau)
        v[at] = vi
        a[at] *= exp(mu * (sample / vi if vi > 0.0 else 0.0))
        return a[at]

    @njit
    def fused_columns(i0, i1, lo, db, woff, voff, ncls, coff, kept, theta, h, trace, rows, x_t, x_tp1, gamma_tp1,
               bounds, inv_tau, a, v, meta, rate, dlv, acc):  # fmt: skip
        """Autostep's meta step and update in one walk over the rows of the support, x_t and x_tp1, for a run of
        demons none of which has M > 1: on a row of x_t each weight's meta step, then at once its theta and h
        (theta += alpha delta e; h = h [1 - alpha e]^+ + alpha delta e, from h as the meta step read it), the
        same operations in the same order as the two passes, so the same numbers; eight numbers per weight of
        x_t read or written instead of ten."""
        s = j = m = 0  # positions in the support, x_t and x_tp1
        while True:
            row, in_support, on_x, on_next, s, j, m = _walk(rows, kept, s, x_t, j, x_tp1, m)
            if row < 0:
                break
            base = _at(woff + row * db)
            tr = voff + row * ncls
            for c in range(ncls if on_x or in_support else 0):
                c0, c1 = max(bounds[c], i0), min(bounds[c + 1], i1)
                e = trace[tr + c]
                if on_x and e != 0.0:
                    for i in range(c0, c1):
                        u = _at(i)
                        at = base + u
                        h_i = h[at]
                        step = meta_step(at, u, meta[_at(lo + i)], e, inv_tau, a, v, h, rate, dlv) * rate[u] * e
                        change = step * dlv[u]
                        theta[at] += change
                        h[at] = h_i * max(1.0 - step, 0.0) + change
                elif on_x:  # a row of x_t whose trace was cut: the meta step only
                    for i in range(c0, c1):
                        u = _at(i)
                        meta_step(base + u, u, meta[_at(lo + i)], e, inv_tau, a, v, h, rate, dlv)
                elif e != 0.0:
                    _trace_update(c0, c1, base, e, a, rate, dlv, theta, h)
            if on_next:
                _add_row(i0, i1, base, theta, acc)

    @njit
    def adaptive_columns(code, i0, i1, lo, db, woff, voff, ncls, coff, nrows, kept, theta, h, trace, rows, x_t, x_tp1,
                         dcls, alpha, r, z, gamma_tp1, rho_t, q, delta, o, acc):  # fmt: skip
        """Columns i0 <= i < i1 of a TIDBD / Autostep block; h lives in w.

        Each class's demons in one contiguous, branch-free run (feature-major, as the other kernels): a
        frozen demon enters with rate 0 and delta 0, which leaves its weights, h, v and step sizes as they
        are. First the values at x_tp1 under the weights before the step (then the TD errors); then either
        the meta step on the rows of x_t and the update over the support fused with reading the new values
        at x_tp1, or, when no demon of the run can have M > 1, both in one walk (`fused_columns`). Autostep's
        effective step size alpha . e (x_t - gamma x_tp1) is summed on a row of x_tp1 alone (whose step
        sizes do not move) in the first pass, on a row of x_t after its step sizes moved.
        """
        autostep = code == AUTOSTEP
        a, v, scale, meta, bounds = o.step_a, o.step_v, o.ascale, o.meta, o.bounds
        upper, rate, dlv, effective = o.scratch[4], o.scratch[5], o.scratch[6], o.scratch[7]
        inv_tau = 1.0 / o.tau[0]
        for i in range(i0, i1):
            acc[i] = 0.0
            effective[i] = 0.0
            upper[i] = 0.0
        # The values at x_tp1; Autostep: the effective step size on rows of x_tp1 alone, and on the rows of x_t
        # sum alpha_i |e (1 - gamma [on x_tp1])| with the step sizes before the meta step (`upper`).
        j = 0
        m = 0
        while j < x_t.shape[0] or m < x_tp1.shape[0]:
            row = _next_row(x_t, x_t.shape[0], j, x_tp1, m)
            on_x = j < x_t.shape[0] and x_t[j] == row
            on_next = m < x_tp1.shape[0] and x_tp1[m] == row
            j += 1 if on_x else 0
            m += 1 if on_next else 0
            base = _at(woff + row * db)
            if on_next:
                _add_row(i0, i1, base, theta, acc)
            for c in range(ncls if autostep else 0):
                e = trace[voff + row * ncls + c]
                if e != 0.0:
                    g = gamma_tp1[coff + c]
                    c0, c1 = max(bounds[c], i0), min(bounds[c + 1], i1)
                    if on_x:
                        _effective_run(c0, c1, base, abs(e * (1.0 - g * (1.0 if on_next else 0.0))), a, upper)
                    else:
                        _effective_run(c0, c1, base, e * -g, a, effective)
        _errors(code, i0, i1, lo, dcls, alpha, r, z, gamma_tp1, rho_t, q, acc, delta, o)
        for i in range(i0, i1):
            acc[i] = 0.0  # the new values at x_tp1, summed in the last pass
        # M_i = rate_i alpha . e (x_t - gamma x_tp1) <= rate_i exp(mu_i) upper_i, as |the meta step's argument|
        # <= mu_i; with a margin for the rounding of the sums, no step size of such a demon is divided by M.
        fused = autostep
        for i in range(i0, i1):
            bound = rate[i] * (math.exp(meta[lo + i]) * upper[i] * (1.0 + 1e-9) + abs(effective[i]) * 1e-9)
            fused = fused and bound <= 1.0
        if fused:
            fused_columns(i0, i1, lo, db, woff, voff, ncls, coff, kept, theta, h, trace, rows, x_t, x_tp1,
                   gamma_tp1, bounds, inv_tau, a, v, meta, rate, dlv, acc)  # fmt: skip
            return
        # The meta step on the rows of x_t (where phi_i = 1): alpha_i *= exp(meta delta h_i [/ v_i]); Autostep
        # adds alpha_i e_i (1 - gamma_tp1 [phi'_i]) to the effective step size there.
        m = 0
        for j in range(x_t.shape[0]):
            row = x_t[j]
            base = _at(woff + row * db)
            tr = voff + row * ncls
            while m < x_tp1.shape[0] and x_tp1[m] < row:
                m += 1
            on_next = 1.0 if m < x_tp1.shape[0] and x_tp1[m] == row else 0.0
            for c in range(ncls):
                c0, c1 = max(bounds[c], i0), min(bounds[c + 1], i1)
                e = trace[tr + c]
                if not autostep:
                    for i in range(c0, c1):
                        u = _at(i)
                        at = base + u
                        a[at] *= math.exp(meta[_at(lo + i)] * dlv[u] * h[at])
                    continue
                coeff = e * (1.0 - gamma_tp1[coff + c] * on_next)
                for i in range(c0, c1):
                    u = _at(i)
                    effective[u] += meta_step(base + u, u, meta[_at(lo + i)], e, inv_tau, a, v, h, rate, dlv) * coeff
        if autostep:  # every step size divided by M = max(1, the effective step size)
            for i in range(i0, i1):
                m_i = effective[i] * rate[i]
                if m_i > 1.0:
                    scale[lo + i] /= m_i
                    rate[i] /= m_i
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
                        _trace_update(c0, c1, base, e, a, rate, dlv, theta, h)
            if on_next:
                _add_row(i0, i1, base, theta, acc)

    return adaptive_columns


@njit(cache=True, inline="always")
def _trace_update(c0, c1, base, e, a, rate, dlv, theta, h):
    """theta += alpha delta e and h += alpha delta e over one class's run of demons at a row outside x_t."""
    for i in range(c0, c1):
        u = _at(i)
        at = base + u
        change = a[at] * rate[u] * e * dlv[u]
        theta[at] += change
        h[at] += change


@njit(cache=True, inline="always")
def _add_row(i0, i1, base, theta, acc):
    """acc += the weight row at base, columns i0 <= i < i1 (the values at x_tp1, row by row)."""
    for i in range(i0, i1):
        u = _at(i)
        acc[u] += theta[base + u]


@njit(cache=True, inline="always")
def _effective_run(c0, c1, base, coeff, a, effective):
    """effective += alpha coeff over one class's run of demons at one row (coeff: e (phi - gamma_tp1 phi'))."""
    for i in range(c0, c1):
        u = _at(i)
        effective[u] += a[base + u] * coeff


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


@njit(cache=True, inline="always")
def _exp_tiny(x):
    """exp(x) for |x| <= TINY_EXP: its Taylor polynomial of degree 6 (the remainder is below 2e-18 relative, under
    the double's rounding), three multiply-adds fewer than `_exp_small`."""
    return 1.0 + x * (1.0 + x * (0.5 + x * (1.0 / 6 + x * (1.0 / 24 + x * (1.0 / 120 + x * (1.0 / 720))))))


@njit(cache=True, inline="always")
def _exp(x):
    """math.exp, as a jitted function that `_autostep_meta` can take."""
    return math.exp(x)


_adaptive_tiny = _adaptive_kernel(_exp_tiny)
_adaptive_small = _adaptive_kernel(_exp_small)
_adaptive_any = _adaptive_kernel(_exp)


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
