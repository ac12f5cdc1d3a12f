"""Compiled kernels (numba) of the one engine's block step: `scale.py`'s equations, in place, sparse traces.

`fast.py` calls `_step` once per group and step. A group's numbers live in flat buffers:

* weights of block b: `[n_b, Db]` row-major (feature-major) at its offset;
* traces of block b: `[n_b, C_b]`, one column per trace class, zero off the support;
* the support of block b: its rows in increasing order, so that the pass over it walks memory forward
  (sorted rows ran 1.4 times faster than the same rows in arrival order).

One step of a block: the values at x_{t+1}, one merge of x_t's rows into the support (with the new
values of a shared trace and the cut), one pass over the support's weight rows (`w . e`, and the theta
and w updates, each weight row read and written once; the w term at x_t is fused in), then the
correction at x_{t+1} fused with reading the new values. Rows are read four at a time and updated two at
a time: more memory streams in flight made sparse rows 1.3 to 1.6 times faster. A demon whose step
sizes are 0 (frozen) stays exactly as it is.

`_step` splits a block's step in two: `_merge` (the traces: nothing per demon) and `_columns` (every
demon's numbers, touching only its own columns), so that a block of at least PARALLEL_MIN demons can
learn on several threads, each over a run of its demons (`_columns_parallel`), with the same operations
in the same order as on one thread: the result does not depend on the thread count, to the last bit.
Offsets into the flat buffers are unsigned (`_at`), so that row loops load contiguous vectors.

The kernels compile without numba's reference counting (`_nrt=False`): they allocate nothing and keep
no array past the call, so the count that numba takes and gives back for every array passed to a
function (an atomic add each, 40 to 60 arrays a call here) buys nothing; it was 44% of a thesis-scale
step (perf), and dropping it made the thesis loop 2.1 times faster. A kernel compiled so cannot
allocate (numba refuses to compile it) and passes the setting down to what it calls, unless the callee
sets `_nrt=True` (`_columns_parallel`, which allocates its scratch).

Why one module of about 780 lines: the kernels call one another in the hot loop, and numba specialises
and inlines calls best within one module (its cache is keyed per module as well).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit, prange

from horde.core.policies import EPSILON_GREEDY, FIXED, SOFTMAX, TIE_TOLERANCE
from horde.core.scale import LEARNER_CODES

TD, GTD, GQ = LEARNER_CODES["td"], LEARNER_CODES["gtd"], LEARNER_CODES["gq"]
ONLINE = LEARNER_CODES["true_online_td"]  # this code and above: adaptive_kernels.online_step learns the block
# The kernels' compile options: cached, without reference counting (module docstring). numba's type stubs
# do not list `_nrt`, hence the dicts.
NO_NRT: dict[str, Any] = {"cache": True, "_nrt": False}
WITH_NRT: dict[str, Any] = {"_nrt": True}
# Columns of the block table.
B_LEARNER, B_POLICY, B_LO, B_HI, B_ROWS, B_WOFF, B_TOFF, B_VOFF, B_NCLS, B_COFF = range(10)


@njit(**NO_NRT)
def _value_policy(kind, q, temperature, epsilon, out):
    """out[:A] = greedy / softmax / epsilon-greedy probabilities over action values q[:A] (policies.py)."""
    A = out.shape[0]  # the world's number of actions, from the arrays (four in the grid world)
    best = q[0]
    for a in range(1, A):
        best = max(best, q[a])
    if kind == SOFTMAX:
        zmax = q[0] / temperature
        for a in range(1, A):
            zmax = max(zmax, q[a] / temperature)
        total = 0.0
        for a in range(A):
            out[a] = math.exp(q[a] / temperature - zmax)
            total += out[a]
        for a in range(A):
            out[a] = out[a] / total
        return
    count = 0
    for a in range(A):
        if q[a] >= best - TIE_TOLERANCE:
            count += 1
    for a in range(A):
        greedy = (1.0 if q[a] >= best - TIE_TOLERANCE else 0.0) / count
        out[a] = epsilon / A + (1.0 - epsilon) * greedy if kind == EPSILON_GREEDY else greedy


@njit(**NO_NRT)
def _sum_rows(flat, start, x, db, acc):
    """acc += the rows x of the [n, db] array at flat[start:], four rows at a time (acc may be a run of
    columns: start then points at its first column, and db stays the row length).

    Offsets into the flat buffers are unsigned (`_at`): numba wraps a signed index that may be negative,
    which turns the loop's loads into gathers (2 to 8 times slower); a slice per row avoids that too,
    but costs a reference count per row, which tiny blocks feel."""
    width = acc.shape[0]
    k = x.shape[0]
    j = 0
    while j + 4 <= k:
        o0 = _at(start + x[j] * db)
        o1 = _at(start + x[j + 1] * db)
        o2 = _at(start + x[j + 2] * db)
        o3 = _at(start + x[j + 3] * db)
        for i in range(width):
            u = _at(i)
            acc[i] += ((flat[o0 + u] + flat[o1 + u]) + flat[o2 + u]) + flat[o3 + u]
        j += 4
    while j < k:
        o0 = _at(start + x[j] * db)
        for i in range(width):
            acc[i] += flat[o0 + _at(i)]
        j += 1


@njit(**NO_NRT, inline="always")
def _at(offset):
    """An offset into a flat buffer as an unsigned integer (never wrapped around: see `_sum_rows`)."""
    return np.uint64(offset)


@njit(**NO_NRT)
def _read_values(bi, b, n_s, theta, x, out):
    """Values at active state features x under the current weights: out[a, :Db] for a < A (GQ) or a = 0."""
    _read_range(bi, b, n_s, theta, x, 0, bi[b, B_HI] - bi[b, B_LO], out)


@njit(**NO_NRT)
def _read_range(bi, b, n_s, theta, x, i0, i1, out):
    """`_read_values` for the block's demons i0 <= i < i1 only: out[a, i0:i1]."""
    lo, hi, woff = bi[b, B_LO], bi[b, B_HI], bi[b, B_WOFF]
    db = hi - lo
    A = out.shape[0]
    actions = A if bi[b, B_LEARNER] == GQ else 1
    for a in range(actions):
        acc = out[a, i0:i1]
        acc[:] = 0.0
        _sum_rows(theta, woff + a * n_s * db + i0, x, db, acc)


@njit(**NO_NRT)
def _target(bi, b, i, dcls, temperature, epsilon, pi_given, values, scratch_q, out):
    """out[:A] = the target policy of demon lo + i at the state whose values are values[:, i]."""
    A = out.shape[0]
    d = bi[b, B_LO] + i
    kind = bi[b, B_POLICY]
    if kind == FIXED:
        for a in range(A):
            out[a] = pi_given[dcls[d], a]
        return
    for a in range(A):
        scratch_q[a] = values[a, i]
    _value_policy(kind, scratch_q, temperature[d], epsilon[d], out)


@njit(**NO_NRT)
def _observe_block(bi, b, dcls, temperature, epsilon, pi_given, values, q, pi, pred, scratch_q, scratch_pi):
    """Store values, policies and predictions of block b read at a state (`values` from _read_values)."""
    _observe_range(bi, b, 0, bi[b, B_HI] - bi[b, B_LO], dcls, temperature, epsilon, pi_given, values, q, pi, pred,
                   scratch_q, scratch_pi)  # fmt: skip


@njit(**NO_NRT)
def _observe_range(bi, b, i0, i1, dcls, temperature, epsilon, pi_given, values, q, pi, pred, scratch_q, scratch_pi):
    """`_observe_block` for the block's demons i0 <= i < i1 only."""
    A = q.shape[1]
    lo = bi[b, B_LO]
    gq = bi[b, B_LEARNER] == GQ
    for i in range(i0, i1):
        d = lo + i
        if not gq:
            q[d, 0] = values[0, i]
            pred[d] = values[0, i]
            continue
        _target(bi, b, i, dcls, temperature, epsilon, pi_given, values, scratch_q, scratch_pi)
        total = 0.0
        for a in range(A):
            q[d, a] = values[a, i]
            pi[d, a] = scratch_pi[a]
            total += scratch_pi[a] * values[a, i]
        pred[d] = total


@njit(**NO_NRT)
def _observe(
    bi,
    n_s,
    dcls,
    temperature,
    epsilon,
    theta,
    trace,
    support,
    nnz,
    x,
    pi_given,
    gamma,
    q,
    pi,
    pred,
    values,
    scratch_q,
    scratch_pi,
):
    gamma[:] = 0.0
    for b in range(bi.shape[0]):
        toff, voff, ncls = bi[b, B_TOFF], bi[b, B_VOFF], bi[b, B_NCLS]
        for s in range(nnz[b]):
            row = support[toff + s]
            trace[voff + row * ncls : voff + (row + 1) * ncls] = 0.0
        nnz[b] = 0
        _read_values(bi, b, n_s, theta, x, values)
        _observe_block(bi, b, dcls, temperature, epsilon, pi_given, values, q, pi, pred, scratch_q, scratch_pi)


@njit(**NO_NRT)
def _update_each(th, wr, ev, f, td, ad, awd, step_x, w_dot_e, owed):
    """One support row with a trace value per demon (ev): the updates of the one-class row in `_columns`."""
    db = th.shape[0]
    if td:
        for i in range(db):
            th[i] += ad[i] * np.float64(ev[i])
        return
    for i in range(db):
        e = np.float64(ev[i])
        wv = wr[i]
        w_dot_e[i] += wv * e
        th[i] += ad[i] * e - f * owed[i]
        wr[i] = wv + awd[i] * e - f * step_x[i]


@njit(**NO_NRT)
def _update_each_pair(th0, w0, ev0, f0, th1, w1, ev1, f1, td, ad, awd, step_x, w_dot_e, owed):
    """Two support rows with a trace value per demon: the updates of the one-class pair in `_columns`."""
    db = th0.shape[0]
    if td:
        for i in range(db):
            a = ad[i]
            th0[i] += a * np.float64(ev0[i])
            th1[i] += a * np.float64(ev1[i])
        return
    for i in range(db):
        a = ad[i]
        aw = awd[i]
        sx = step_x[i]
        e0 = np.float64(ev0[i])
        e1 = np.float64(ev1[i])
        v0 = w0[i]
        v1 = w1[i]
        w_dot_e[i] += v0 * e0 + v1 * e1
        th0[i] += a * e0 - f0 * owed[i]
        th1[i] += a * e1 - f1 * owed[i]
        w0[i] = v0 + aw * e0 - f0 * sx
        w1[i] = v1 + aw * e1 - f1 * sx


@njit(**NO_NRT)
def _decay_classes(tr, on_x, decay, add, cut, times):
    """New trace values of one row, one per class, in place (x_t's value on the row: `times`); entries below the
    cut become 0.

    Branch-free, so that it vectorizes. Returns whether any entry is left."""
    left = 0
    if on_x:
        for c in range(tr.shape[0]):
            v = tr[c] * decay[c] + add[c] * times
            v = v if abs(v) >= cut else 0.0
            tr[c] = v
            left += 1 if v != 0.0 else 0
    else:
        for c in range(tr.shape[0]):
            v = tr[c] * decay[c]
            v = v if abs(v) >= cut else 0.0
            tr[c] = v
            left += 1 if v != 0.0 else 0
    return left > 0


@njit(**NO_NRT)
def _step(
    bi,
    lam,
    alpha,
    alpha_w,
    temperature,
    epsilon,
    dcls,
    cls_lo,
    cls_hi,
    cut,
    n_s,
    theta,
    w,
    trace,
    support,
    rows,
    rows_e,
    rows_f,
    nnz,
    x_t,
    action,
    b_prob,
    x_tp1,
    r,
    z,
    gamma_tp1,
    rho_t,
    pi_given,
    gamma,
    q,
    pi,
    pred,
    delta,
    touched,
    values,
    pi_next,
    ad,
    awd,
    w_dot_e,
    w_dot_x,
    owed,
    mark,
    ex,
    ev,
    decay,
    add,
    scratch_q,
    scratch_pi,
    threads=1,
):
    """One transition for every block (the equations of scale.step), in place. x_t and x_tp1 are sorted.

    Per block: `_merge` (the trace classes' decay, x_t's rows merged into the support, the cut), then
    `_columns` over the block's demons, which touches only their columns: with `threads` > 1 and at
    least PARALLEL_MIN demons, the demons are split into runs of columns learned by that many threads
    (`_columns_parallel`). Every number is computed by the same operations in the same order whatever
    the split, so the result does not depend on the number of threads, to the last bit."""
    for b in range(bi.shape[0]):
        if bi[b, B_LEARNER] >= ONLINE:  # fast.py runs adaptive_kernels.online_step for these blocks
            continue
        kept, dropped = _merge(bi, b, lam[b], cut, n_s, trace, support, rows, rows_e, rows_f, nnz, touched, x_t,
                               action, b_prob, rho_t, pi, gamma, decay, add)  # fmt: skip
        db = bi[b, B_HI] - bi[b, B_LO]
        marking = bi[b, B_LEARNER] == GQ and bi[b, B_NCLS] > 1  # e . x_bar(s_{t+1}, a) per demon (`_gather`)
        if marking:
            for a in range(q.shape[1]):
                for j in range(x_tp1.shape[0]):
                    mark[a * n_s + x_tp1[j]] += 1
        if threads > 1 and db >= PARALLEL_MIN:
            _columns_parallel(threads, bi, b, kept, dropped, lam[b], alpha, alpha_w, temperature, epsilon, dcls,
                              cls_lo, cls_hi, n_s, theta, w, trace, rows, rows_e, rows_f, x_t, action, x_tp1, r, z,
                              gamma_tp1, pi_given, q, pi, pred, delta, values, pi_next, ad, awd, w_dot_e, w_dot_x,
                              owed, mark, ex, ev)  # fmt: skip
        else:
            _columns(bi, b, 0, db, kept, dropped, lam[b], alpha, alpha_w, temperature, epsilon, dcls, cls_lo, cls_hi,
                     n_s, theta, w, trace, rows, rows_e, rows_f, x_t, action, x_tp1, r, z, gamma_tp1, pi_given, q, pi,
                     pred, delta, values, pi_next, ad, awd, w_dot_e, w_dot_x, owed, mark, ex, ev, scratch_q,
                     scratch_pi)  # fmt: skip
        if marking:
            for a in range(q.shape[1]):
                for j in range(x_tp1.shape[0]):
                    mark[a * n_s + x_tp1[j]] = 0
        coff = bi[b, B_COFF]
        for c in range(bi[b, B_NCLS]):
            gamma[coff + c] = gamma_tp1[coff + c]


@njit(**NO_NRT, inline="always")
def _merge(bi, b, lam_b, cut, n_s, trace, support, rows, rows_e, rows_f, nnz, touched, x_t, action, b_prob, rho_t,
           pi, gamma, decay, add):  # fmt: skip
    """Block b's traces for this step: every class's decay (gamma_t lambda rho_t) and what x_t adds (rho_t
    for TD/GTD, 1 for GQ); x_t's rows merged into the support (both sorted), each row's trace values
    decayed and cut. Nothing per demon is touched, so the block's columns can be learned apart.

    Returns (kept, dropped): the rows left with a trace, in rows[:kept] in increasing order (the new
    support; rows_f x_t's value on the row, rows_e the value of a one-class trace); and, for GTD / GQ,
    the rows of x_t left with none (their w still loses alpha_w (w . x_t) x_t), at the end of `rows`.

    An index listed twice in x_t (a table feature of value 2; sorted, so the repeats are adjacent) is one
    row whose trace gains twice what x_t adds, rows_f 2, and, if dropped, is listed twice among the dropped.
    """
    learner, kind = bi[b, B_LEARNER], bi[b, B_POLICY]
    lo, toff, voff, ncls, coff = bi[b, B_LO], bi[b, B_TOFF], bi[b, B_VOFF], bi[b, B_NCLS], bi[b, B_COFF]
    gq = learner == GQ
    td = learner == TD
    own = kind != FIXED
    shift = action * n_s if gq else 0
    for c in range(ncls):
        rho = pi[lo + c, action] / b_prob if own else rho_t[coff + c]
        decay[c] = gamma[coff + c] * lam_b * rho
        add[c] = 1.0 if gq else rho
    k = x_t.shape[0]
    end = rows.shape[0] - 1
    old = nnz[b]
    i_old = 0
    j_new = 0
    out = 0
    dropped = 0
    times = 1.0  # x_t's value on the row: how often its index is listed (1 but for a table's repeats)
    while i_old < old or j_new < k:
        if j_new >= k or (i_old < old and support[toff + i_old] < shift + x_t[j_new]):
            row = support[toff + i_old]
            on_x = False
            i_old += 1
        else:
            row = shift + x_t[j_new]
            on_x = True
            if i_old < old and support[toff + i_old] == row:
                i_old += 1
            j_new += 1
            while j_new < k and shift + x_t[j_new] == row:  # an index listed again: feature value 2, 3, ...
                j_new += 1
                times += 1.0
        if ncls == 1:
            v = trace[voff + row] * decay[0]
            if on_x:
                v += add[0] * times
            trace[voff + row] = v if abs(v) >= cut else 0.0
            left = trace[voff + row] != 0.0
            rows_e[out] = trace[voff + row]  # the stored value (in the layout's dtype)
        else:
            left = _decay_classes(trace[voff + row * ncls : voff + (row + 1) * ncls], on_x, decay, add, cut, times)
        if not left:
            if on_x and not td:
                for _ in range(int(times)):  # w loses alpha_w (w . x_t) x_t: once per unit of the feature's value
                    rows[end - dropped] = row
                    dropped += 1
            times = 1.0
            continue
        rows[out] = row
        rows_f[out] = times if on_x else 0.0  # x_t's value on this row (the w update's factor)
        times = 1.0
        out += 1
    for s in range(out):  # element by element: a slice copy may allocate (kernels run without NRT)
        support[toff + s] = rows[s]
    nnz[b] = out
    touched[b] = out
    return out, dropped


PARALLEL_MIN = 512  # demons of a block from which its columns are split over threads
ALIGN = 8  # column runs start at multiples of 8 numbers (64 bytes, a cache line) within a row


@njit(cache=True, parallel=True, **WITH_NRT)  # allocates: NRT on (a caller without NRT would pass its flag down)
def _columns_parallel(threads, bi, b, kept, dropped, lam_b, alpha, alpha_w, temperature, epsilon, dcls, cls_lo,
                      cls_hi, n_s, theta, w, trace, rows, rows_e, rows_f, x_t, action, x_tp1, r, z, gamma_tp1,
                      pi_given, q, pi, pred, delta, values, pi_next, ad, awd, w_dot_e, w_dot_x, owed, mark, ex,
                      ev):  # fmt: skip
    """`_columns` of block b on `threads` threads, each over one run of the block's demons."""
    db = bi[b, B_HI] - bi[b, B_LO]
    runs = min(threads, (db + ALIGN - 1) // ALIGN)
    width = ((db + runs - 1) // runs + ALIGN - 1) // ALIGN * ALIGN
    scratch = np.empty((runs, 2, q.shape[1]))
    for t in prange(runs):
        i0 = min(t * width, db)
        i1 = min(i0 + width, db)
        _columns(bi, b, i0, i1, kept, dropped, lam_b, alpha, alpha_w, temperature, epsilon, dcls, cls_lo, cls_hi,
                 n_s, theta, w, trace, rows, rows_e, rows_f, x_t, action, x_tp1, r, z, gamma_tp1, pi_given, q, pi,
                 pred, delta, values, pi_next, ad, awd, w_dot_e, w_dot_x, owed, mark, ex, ev, scratch[t, 0],
                 scratch[t, 1])  # fmt: skip


@njit(**NO_NRT)
def _columns(bi, b, i0, i1, kept, dropped, lam_b, alpha, alpha_w, temperature, epsilon, dcls, cls_lo, cls_hi, n_s,
             theta, w, trace, rows, rows_e, rows_f, x_t, action, x_tp1, r, z, gamma_tp1, pi_given, q, pi, pred,
             delta, values, pi_next, ad, awd, w_dot_e, w_dot_x, owed, mark, ex, ev, scratch_q,
             scratch_pi):  # fmt: skip
    """Block b's demons i0 <= i < i1 learn the transition, after `_merge`: only their columns of the
    weights and of the per-demon buffers (values, pi_next, ad, awd, w_dot_e, w_dot_x, owed, ex, ev) are
    touched.

    The gradient correction at x_{t+1} (theta -= alpha gamma (1 - lambda) (w . e) x_bar_{t+1}; for GQ on
    every action's rows, weighted by the target policy there) is owed rather than applied: `owed[a, d]`
    holds it, and the next step pays it on its x_t's rows (the same rows). GTD pays in its pass over the
    support, which visits them anyway; GQ while it reads its values at x_{t+1} (the other actions' rows
    are in no support). The new values at s_{t+1} then come from the update's algebra instead of a pass
    that corrects and reads those rows again: theta' . x = theta . x + alpha delta (e . x) - owed (x . x),
    with e . x one sum per trace class, or per demon from the support pass (`mark`, `ex`). `settle_owed`
    pays what is owed before anyone else reads theta (a call's end, an episode's end, a freeze)."""
    learner, kind = bi[b, B_LEARNER], bi[b, B_POLICY]
    lo, hi = bi[b, B_LO], bi[b, B_HI]
    woff, voff, ncls, coff = bi[b, B_WOFF], bi[b, B_VOFF], bi[b, B_NCLS], bi[b, B_COFF]
    db = hi - lo
    width = i1 - i0
    gq = learner == GQ
    td = learner == TD
    own = kind != FIXED
    A = q.shape[1]
    shift = action * n_s if gq else 0
    owing = learner == GTD  # pays on the support (GTD follows given policies: never own values); GQ pays below

    # Values at s_{t+1} under the weights before this update, the target policy there, delta.
    if gq:
        for a in range(A):
            _pay_and_read(theta, woff + a * n_s * db + i0, x_t, x_tp1, db, owed[a, lo + i0 : lo + i1],
                          values[a, i0:i1])  # fmt: skip
            for i in range(i0, i1):
                ex[a, i] = 0.0
    else:
        _read_range(bi, b, n_s, theta, x_tp1, i0, i1, values)
    if owing:  # theta still owes the last step's correction on x_t's rows
        shared = _dot(x_t, x_tp1)
        for i in range(i0, i1):
            values[0, i] -= owed[0, lo + i] * shared
    for i in range(i0, i1):
        d = lo + i
        g1 = gamma_tp1[dcls[d]]
        if gq:
            _target(bi, b, i, dcls, temperature, epsilon, pi_given, values, scratch_q, scratch_pi)
            v_next = 0.0
            for a in range(A):
                pi_next[a, i] = scratch_pi[a]
                v_next += scratch_pi[a] * values[a, i]
            v_t = q[d, action]
        else:
            v_next = values[0, i]
            v_t = q[d, 0]
        dl = r[d] + (1.0 - g1) * z[d] + g1 * v_next - v_t
        delta[d] = dl
        # a frozen demon (step size 0) stays exactly as it is, even when its delta is not finite
        ad[i] = alpha[d] * dl if alpha[d] != 0.0 else 0.0
        awd[i] = alpha_w[d] * dl if alpha_w[d] != 0.0 else 0.0
        w_dot_e[i] = 0.0
        w_dot_x[i] = 0.0

    # alpha_w (w . x_t) under the old w; the rows of x_t left without a trace lose it here.
    step_x = w_dot_x[i0:i1]
    if not td:
        _sum_rows(w, woff + shift * db + i0, x_t, db, step_x)
        for i in range(width):
            step_x[i] = step_x[i] * alpha_w[lo + i0 + i] if alpha_w[lo + i0 + i] != 0.0 else 0.0
        end = rows.shape[0] - 1
        owed_ = owed[0, lo + i0 : lo + i1]  # (GQ has paid already: 0)
        for j in range(dropped):
            start = _at(woff + rows[end - j] * db + i0)
            for i in range(width):
                w[start + _at(i)] -= step_x[i]
                theta[start + _at(i)] -= owed_[i]

    # The weight pass over the support, in row order, two rows at a time. One class: its trace value
    # per row; several: each row's values spread over the classes' demons (own-value blocks: the
    # trace row itself).
    ad_, awd_, dot_e = ad[i0:i1], awd[i0:i1], w_dot_e[i0:i1]
    if ncls == 1:
        # Written out here rather than in a function called per row: such a call takes and gives back a
        # count of each array it is passed, most of a step's time in a block of one demon.
        s = 0
        while s < kept:
            e0 = rows_e[s]
            f0 = rows_f[s]
            u0 = _at(woff + rows[s] * db + i0)
            if s + 1 < kept:  # two rows: theta += ad e; GTD / GQ: w . e, w += awd e - f alpha_w (w . x_t)
                e1 = rows_e[s + 1]
                f1 = rows_f[s + 1]
                u1 = _at(woff + rows[s + 1] * db + i0)
                if td:
                    for i in range(width):
                        a = ad[i0 + i]
                        theta[u0 + _at(i)] += a * e0
                        theta[u1 + _at(i)] += a * e1
                else:
                    for i in range(width):
                        a = ad[i0 + i]
                        aw = awd[i0 + i]
                        sx = step_x[i]
                        o = owed[0, lo + i0 + i]
                        j0 = u0 + _at(i)
                        j1 = u1 + _at(i)
                        v0 = w[j0]
                        v1 = w[j1]
                        w_dot_e[i0 + i] += v0 * e0 + v1 * e1
                        theta[j0] += a * e0 - f0 * o
                        theta[j1] += a * e1 - f1 * o
                        w[j0] = v0 + aw * e0 - f0 * sx
                        w[j1] = v1 + aw * e1 - f1 * sx
                s += 2
            else:  # the last row alone
                if td:
                    for i in range(width):
                        theta[u0 + _at(i)] += ad[i0 + i] * e0
                else:
                    for i in range(width):
                        j0 = u0 + _at(i)
                        wv = w[j0]
                        w_dot_e[i0 + i] += wv * e0
                        theta[j0] += ad[i0 + i] * e0 - f0 * owed[0, lo + i0 + i]
                        w[j0] = wv + awd[i0 + i] * e0 - f0 * step_x[i]
                s += 1
    else:
        e0 = ev[0, i0:i1]
        e1 = ev[1, i0:i1]
        s = 0
        while s < kept:
            pair = s + 1 < kept
            r0 = rows[s]
            r1 = rows[s + 1] if pair else r0
            if own:
                e0 = trace[voff + r0 * ncls + i0 : voff + r0 * ncls + i1]
                e1 = trace[voff + r1 * ncls + i0 : voff + r1 * ncls + i1]
            else:
                _spread(trace, voff + r0 * ncls, ncls, cls_lo, cls_hi, coff, i0, i1, e0)
                if pair:
                    _spread(trace, voff + r1 * ncls, ncls, cls_lo, cls_hi, coff, i0, i1, e1)
            b0 = woff + r0 * db + i0
            if pair:
                b1 = woff + r1 * db + i0
                _update_each_pair(theta[b0 : b0 + width], w[b0 : b0 + width], e0, rows_f[s], theta[b1 : b1 + width],
                                  w[b1 : b1 + width], e1, rows_f[s + 1], td, ad_, awd_, step_x, dot_e,
                                  owed[0, lo + i0 : lo + i1])  # fmt: skip
                if gq:
                    _gather(mark, r1, n_s, e1, ex, i0)
                s += 2
            else:
                _update_each(theta[b0 : b0 + width], w[b0 : b0 + width], e0, rows_f[s], td, ad_, awd_, step_x, dot_e,
                             owed[0, lo + i0 : lo + i1])  # fmt: skip
                s += 1
            if gq:
                _gather(mark, r0, n_s, e0, ex, i0)

    # The correction at x_bar_{t+1} (owed: see above) and the new values at s_{t+1}.
    if not td:
        for i in range(i0, i1):
            a_i = alpha[lo + i]
            w_dot_e[i] = a_i * gamma_tp1[dcls[lo + i]] * (1.0 - lam_b) * w_dot_e[i] if a_i != 0.0 else 0.0
    if gq:
        # As for GTD below, for each action's rows at s_{t+1}; e . x_bar(s_{t+1}, a) from the support pass
        # (`_gather`; one class: one sum per action).
        own_dot = _dot(x_tp1, x_tp1)
        for a in range(A):
            if ncls == 1:
                e_dot_x = 0.0
                for j in range(x_tp1.shape[0]):
                    e_dot_x += np.float64(trace[voff + a * n_s + x_tp1[j]])
                for i in range(i0, i1):
                    ex[a, i] = e_dot_x
            for i in range(i0, i1):
                o = w_dot_e[i] * pi_next[a, i]
                values[a, i] += ad[i] * ex[a, i] - o * own_dot
                owed[a, lo + i] = o
    elif owing:
        # theta' . x_{t+1} = theta . x_{t+1} + alpha delta (e . x_{t+1}) - owed (x_{t+1} . x_{t+1}): the update
        # added alpha delta e to every row (a row cut from the support has trace 0 and was not updated), and
        # x_t's rows paid what they owed (already taken from the values above).
        own_dot = _dot(x_tp1, x_tp1)
        for c in range(ncls):
            c0 = max(cls_lo[coff + c], i0) if ncls > 1 else i0
            c1 = min(cls_hi[coff + c], i1) if ncls > 1 else i1
            if c0 >= c1:
                continue
            e_dot_x = 0.0
            for j in range(x_tp1.shape[0]):
                e_dot_x += np.float64(trace[voff + x_tp1[j] * ncls + c])
            for i in range(c0, c1):
                values[0, i] += ad[i] * e_dot_x - w_dot_e[i] * own_dot
                owed[0, lo + i] = w_dot_e[i]
    else:  # TD: the new values at s_{t+1}, read
        _read_in_pairs(theta, woff + i0, x_tp1, db, values[0, i0:i1])
    _observe_range(bi, b, i0, i1, dcls, temperature, epsilon, pi_given, values, q, pi, pred, scratch_q, scratch_pi)


@njit(**NO_NRT)
def _dot(x, y):
    """x . y for two sorted lists of active features (an index listed twice is a feature of value 2)."""
    total = 0.0
    i = 0
    j = 0
    while i < x.shape[0] and j < y.shape[0]:
        if x[i] < y[j]:
            i += 1
        elif y[j] < x[i]:
            j += 1
        else:
            m, i = listed(x, i, x[i])
            n, j = listed(y, j, y[j])
            total += m * n
    return total


@njit(**NO_NRT, inline="always")
def listed(x, j, row):
    """How often the sorted list x lists `row` from position j on (0, 1, or 2 for a table's repeat, ...),
    and the position past it."""
    count = 0.0
    while j < x.shape[0] and x[j] == row:
        count += 1.0
        j += 1
    return count, j


@njit(**NO_NRT)
def _read_in_pairs(theta, start, x, db, acc):
    """acc = the sum of the rows x, two rows at a time (a run of columns, as in `_sum_rows`).

    TD's read of its new values, as before the sixth session: `_sum_rows`' four rows at a time made TD
    13 to 15 % faster (alternated runs), which would take Autostep under the third of TD's speed that the
    learners issue asks; TD's speed-ups wait on that question (docs/performance.md, "Sixth session")."""
    width = acc.shape[0]
    for i in range(width):
        acc[i] = 0.0
    k = x.shape[0]
    j = 0
    while j + 1 < k:
        u0 = _at(start + x[j] * db)
        u1 = _at(start + x[j + 1] * db)
        for i in range(width):
            acc[i] += theta[u0 + _at(i)] + theta[u1 + _at(i)]
        j += 2
    if j < k:
        u0 = _at(start + x[j] * db)
        for i in range(width):
            acc[i] += theta[u0 + _at(i)]


@njit(**NO_NRT)
def _gather(mark, row, n_s, e, ex, i0):
    """ex[a, i0 + i] += e[i] times how often the support row `row` is listed at s_{t+1} for action a (`mark`)."""
    m = mark[row]
    if m != 0:
        a = row // n_s
        for i in range(e.shape[0]):
            ex[a, i0 + i] += m * np.float64(e[i])


@njit(**NO_NRT)
def _pay_and_read(theta, start, x_t, x_tp1, db, owed, acc):
    """theta pays `owed` on the rows x_t (once per listing), then acc = the sum of the rows x_tp1: one walk
    over the union of the two sorted lists. As in `_sum_rows`, acc may be a run of columns (start at its
    first column, db the row length); `owed` (the same run) is 0 afterwards."""
    width = acc.shape[0]
    for i in range(width):
        acc[i] = 0.0
    nt = x_t.shape[0]
    nn = x_tp1.shape[0]
    j_t = 0
    j_n = 0
    while j_t < nt or j_n < nn:
        row = x_t[j_t] if j_n >= nn or (j_t < nt and x_t[j_t] < x_tp1[j_n]) else x_tp1[j_n]
        m_t, j_t = listed(x_t, j_t, row)
        m_n, j_n = listed(x_tp1, j_n, row)
        u = _at(start + row * db)
        if m_t == 0.0:
            for i in range(width):
                acc[i] += m_n * theta[u + _at(i)]
        elif m_n == 0.0:
            for i in range(width):
                theta[u + _at(i)] -= m_t * owed[i]
        else:
            for i in range(width):
                v = theta[u + _at(i)] - m_t * owed[i]
                theta[u + _at(i)] = v
                acc[i] += m_n * v
    for i in range(width):
        owed[i] = 0.0


@njit(**NO_NRT)
def settle_owed(bi, b, n_s, theta, x, owed):
    """Pay block b's owed gradient correction (`_columns`) on the rows x it is owed on (each action's, for
    GQ), and owe nothing more."""
    learner = bi[b, B_LEARNER]
    if learner != GTD and learner != GQ:
        return
    lo, woff = bi[b, B_LO], bi[b, B_WOFF]
    db = bi[b, B_HI] - lo
    for a in range(owed.shape[0] if learner == GQ else 1):
        for j in range(x.shape[0]):
            u = _at(woff + (a * n_s + x[j]) * db)
            for i in range(db):
                theta[u + _at(i)] -= owed[a, lo + i]
        for i in range(db):
            owed[a, lo + i] = 0.0


@njit(**NO_NRT)
def _spread(trace, start, ncls, cls_lo, cls_hi, coff, i0, i1, out):
    """out[i - i0] = the trace value (trace[start + c]) of the class of demon i, for i0 <= i < i1."""
    for c in range(ncls):
        c0 = max(cls_lo[coff + c], i0)
        c1 = min(cls_hi[coff + c], i1)
        if c0 < c1:
            out[c0 - i0 : c1 - i0] = trace[start + c]
