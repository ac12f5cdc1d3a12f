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
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from horde.core.policies import EPSILON_GREEDY, FIXED, SOFTMAX, TIE_TOLERANCE
from horde.core.scale import LEARNER_CODES

TD, GTD, GQ = LEARNER_CODES["td"], LEARNER_CODES["gtd"], LEARNER_CODES["gq"]
ONLINE = LEARNER_CODES["true_online_td"]  # this code and above: adaptive_kernels.online_step learns the block
# Columns of the block table.
B_LEARNER, B_POLICY, B_LO, B_HI, B_ROWS, B_WOFF, B_TOFF, B_VOFF, B_NCLS, B_COFF = range(10)


@njit(cache=True)
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


@njit(cache=True)
def _sum_rows(flat, start, x, db, acc):
    """acc[:db] += the rows x of the [n, db] array at flat[start:], four rows at a time."""
    k = x.shape[0]
    j = 0
    while j + 4 <= k:
        o0 = start + x[j] * db
        o1 = start + x[j + 1] * db
        o2 = start + x[j + 2] * db
        o3 = start + x[j + 3] * db
        for i in range(db):
            acc[i] += ((flat[o0 + i] + flat[o1 + i]) + flat[o2 + i]) + flat[o3 + i]
        j += 4
    while j < k:
        o0 = start + x[j] * db
        for i in range(db):
            acc[i] += flat[o0 + i]
        j += 1


@njit(cache=True)
def _read_values(bi, b, n_s, theta, x, out):
    """Values at active state features x under the current weights: out[a, :Db] for a < A (GQ) or a = 0."""
    A = out.shape[0]
    lo, hi, woff = bi[b, B_LO], bi[b, B_HI], bi[b, B_WOFF]
    db = hi - lo
    actions = A if bi[b, B_LEARNER] == GQ else 1
    for a in range(actions):
        acc = out[a, :db]
        acc[:] = 0.0
        _sum_rows(theta, woff + a * n_s * db, x, db, acc)


@njit(cache=True)
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


@njit(cache=True)
def _observe_block(bi, b, dcls, temperature, epsilon, pi_given, values, q, pi, pred, scratch_q, scratch_pi):
    """Store values, policies and predictions of block b read at a state (`values` from _read_values)."""
    A = q.shape[1]
    lo, hi = bi[b, B_LO], bi[b, B_HI]
    gq = bi[b, B_LEARNER] == GQ
    for i in range(hi - lo):
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


@njit(cache=True)
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


@njit(cache=True)
def _update_pair(theta, w, b0, b1, db, e0, e1, f0, f1, td, ad, awd, step_x, w_dot_e):
    """Two support rows (at flat offsets b0, b1) of a shared trace: theta += ad e; for GTD/GQ also w . e
    and w += awd e - f alpha_w (w . x_t)  (f = 1 on the rows of x_t, else 0)."""
    if td:
        for i in range(db):
            a = ad[i]
            theta[b0 + i] += a * e0
            theta[b1 + i] += a * e1
        return
    for i in range(db):
        a = ad[i]
        aw = awd[i]
        sx = step_x[i]
        v0 = w[b0 + i]
        v1 = w[b1 + i]
        w_dot_e[i] += v0 * e0 + v1 * e1
        theta[b0 + i] += a * e0
        theta[b1 + i] += a * e1
        w[b0 + i] = v0 + aw * e0 - f0 * sx
        w[b1 + i] = v1 + aw * e1 - f1 * sx


@njit(cache=True)
def _update_one(theta, w, b0, db, e, f, td, ad, awd, step_x, w_dot_e):
    """One support row of a shared trace (as `_update_pair`)."""
    if td:
        for i in range(db):
            theta[b0 + i] += ad[i] * e
        return
    for i in range(db):
        wv = w[b0 + i]
        w_dot_e[i] += wv * e
        theta[b0 + i] += ad[i] * e
        w[b0 + i] = wv + awd[i] * e - f * step_x[i]


@njit(cache=True)
def _update_each(th, wr, ev, f, td, ad, awd, step_x, w_dot_e):
    """One support row with a trace value per demon (ev): the updates of `_update_one`."""
    db = th.shape[0]
    if td:
        for i in range(db):
            th[i] += ad[i] * np.float64(ev[i])
        return
    for i in range(db):
        e = np.float64(ev[i])
        wv = wr[i]
        w_dot_e[i] += wv * e
        th[i] += ad[i] * e
        wr[i] = wv + awd[i] * e - f * step_x[i]


@njit(cache=True)
def _update_each_pair(th0, w0, ev0, f0, th1, w1, ev1, f1, td, ad, awd, step_x, w_dot_e):
    """Two support rows with a trace value per demon: the updates of `_update_pair`."""
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
        th0[i] += a * e0
        th1[i] += a * e1
        w0[i] = v0 + aw * e0 - f0 * sx
        w1[i] = v1 + aw * e1 - f1 * sx


@njit(cache=True)
def _decay_classes(tr, on_x, decay, add, cut):
    """New trace values of one row, one per class, in place; entries below the cut become 0.

    Branch-free, so that it vectorizes. Returns whether any entry is left."""
    left = 0
    if on_x:
        for c in range(tr.shape[0]):
            v = tr[c] * decay[c] + add[c]
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


@njit(cache=True)
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
    ev,
    decay,
    add,
    scratch_q,
    scratch_pi,
):
    """One transition for every block (the equations of scale.step), in place. x_t and x_tp1 are sorted."""
    A = q.shape[1]
    k = x_t.shape[0]
    for b in range(bi.shape[0]):
        learner, kind = bi[b, B_LEARNER], bi[b, B_POLICY]
        if learner >= ONLINE:  # fast.py runs adaptive_kernels.online_step for these blocks
            continue
        lo, hi = bi[b, B_LO], bi[b, B_HI]
        woff, toff, voff, ncls, coff = bi[b, B_WOFF], bi[b, B_TOFF], bi[b, B_VOFF], bi[b, B_NCLS], bi[b, B_COFF]
        db = hi - lo
        gq = learner == GQ
        td = learner == TD
        own = kind != FIXED
        lam_b = lam[b]
        actions = A if gq else 1
        shift = action * n_s if gq else 0

        # Values at s_{t+1} under the weights before this update, the target policy there, delta.
        _read_values(bi, b, n_s, theta, x_tp1, values)
        for i in range(db):
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

        # Trace classes: decay gamma_t lambda rho_t, and what x_t adds (rho_t for TD/GTD, 1 for GQ).
        for c in range(ncls):
            rho = pi[lo + c, action] / b_prob if own else rho_t[coff + c]
            decay[c] = gamma[coff + c] * lam_b * rho
            add[c] = 1.0 if gq else rho

        # alpha_w (w . x_t) under the old w.
        step_x = w_dot_x[:db]
        if not td:
            _sum_rows(w, woff + shift * db, x_t, db, step_x)
            for i in range(db):
                step_x[i] = step_x[i] * alpha_w[lo + i] if alpha_w[lo + i] != 0.0 else 0.0

        # Merge x_t's rows into the support (both sorted). A shared trace gets its new values and the
        # cut here (one number per row), so that the weight pass below sees only the rows it updates.
        old = nnz[b]
        i_old = 0
        j_new = 0
        out = 0
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
            if ncls == 1:
                v = trace[voff + row] * decay[0]
                if on_x:
                    v += add[0]
                trace[voff + row] = v if abs(v) >= cut else 0.0
                if trace[voff + row] == 0.0:
                    if on_x and not td:  # no trace left here, but w still loses alpha_w (w . x_t) x_t
                        wr = w[woff + row * db : woff + (row + 1) * db]
                        for i in range(db):
                            wr[i] -= step_x[i]
                    continue
                rows_e[out] = trace[voff + row]  # the stored value (in the layout's dtype)
            rows[out] = row
            rows_f[out] = 1.0 if on_x else 0.0
            out += 1

        # The weight pass over the merged rows, in row order. One class: two rows at a time. Several
        # classes: each row's trace values (decayed and cut), spread over the classes' demons.
        kept = 0
        if ncls == 1:
            s = 0
            while s + 2 <= out:
                b0 = woff + rows[s] * db
                b1 = woff + rows[s + 1] * db
                _update_pair(theta, w, b0, b1, db, rows_e[s], rows_e[s + 1], rows_f[s], rows_f[s + 1], td, ad, awd,
                             step_x, w_dot_e)  # fmt: skip
                s += 2
            if s < out:
                b0 = woff + rows[s] * db
                _update_one(theta, w, b0, db, rows_e[s], rows_f[s], td, ad, awd, step_x, w_dot_e)
            support[toff : toff + out] = rows[:out]
            kept = out
        else:
            # Several classes: each row's trace values (decayed and cut) per demon, in ev (own-value
            # blocks: the trace row itself); rows left with a trace are updated two at a time.
            pending = -1  # a kept row waiting for a partner
            for s in range(out):
                row = rows[s]
                tr = trace[voff + row * ncls : voff + (row + 1) * ncls]
                if not _decay_classes(tr, rows_f[s] > 0.0, decay, add, cut):
                    if rows_f[s] > 0.0 and not td:
                        wr = w[woff + row * db : woff + (row + 1) * db]
                        for i in range(db):
                            wr[i] -= step_x[i]
                    continue
                support[toff + kept] = row
                kept += 1
                slot = 0 if pending < 0 else 1
                if not own:
                    spread = ev[slot, :db]
                    for c in range(ncls):
                        spread[cls_lo[coff + c] : cls_hi[coff + c]] = tr[c]
                if pending < 0:
                    pending = s
                    continue
                r0, r1 = rows[pending], row
                b0, b1 = woff + r0 * db, woff + r1 * db
                e0 = trace[voff + r0 * ncls : voff + (r0 + 1) * ncls] if own else ev[0, :db]
                e1 = tr if own else ev[1, :db]
                _update_each_pair(
                    theta[b0 : b0 + db],
                    w[b0 : b0 + db],
                    e0,
                    rows_f[pending],
                    theta[b1 : b1 + db],
                    w[b1 : b1 + db],
                    e1,
                    rows_f[s],
                    td,
                    ad,
                    awd,
                    step_x,
                    w_dot_e,
                )
                pending = -1
            if pending >= 0:
                r0 = rows[pending]
                b0 = woff + r0 * db
                e0 = trace[voff + r0 * ncls : voff + (r0 + 1) * ncls] if own else ev[0, :db]
                _update_each(theta[b0 : b0 + db], w[b0 : b0 + db], e0, rows_f[pending], td, ad, awd, step_x, w_dot_e)
        nnz[b] = kept
        touched[b] = kept

        # The correction at x_bar_{t+1}, fused with reading the new values at s_{t+1}.
        correction = w_dot_e[:db]
        if not td:
            for i in range(db):
                a_i = alpha[lo + i]
                correction[i] = a_i * gamma_tp1[dcls[lo + i]] * (1.0 - lam_b) * correction[i] if a_i != 0.0 else 0.0
        mode = 0 if td else (2 if gq else 1)
        for a in range(actions):
            _correct_and_read(theta, woff + a * n_s * db, x_tp1, db, correction, pi_next[a, :db], mode, values[a, :db])
        _observe_block(bi, b, dcls, temperature, epsilon, pi_given, values, q, pi, pred, scratch_q, scratch_pi)
        for c in range(ncls):
            gamma[coff + c] = gamma_tp1[coff + c]


@njit(cache=True)
def _correct_and_read(theta, start, x, db, correction, weight, mode, acc):
    """theta -= correction * weight on the rows x (mode 2: a weight per demon, 1: weight 1, 0: no
    correction), then acc = the sum of those rows: the new values at s_{t+1}. Two rows at a time."""
    k = x.shape[0]
    for i in range(db):
        acc[i] = 0.0
    j = 0
    while j < k:
        pair = j + 1 < k
        b0 = start + x[j] * db
        b1 = start + x[j + 1] * db if pair else b0
        if mode == 2:
            for i in range(db):
                c = correction[i] * weight[i]
                theta[b0 + i] -= c
                if pair:
                    theta[b1 + i] -= c
        elif mode == 1:
            for i in range(db):
                theta[b0 + i] -= correction[i]
                if pair:
                    theta[b1 + i] -= correction[i]
        if pair:
            for i in range(db):
                acc[i] += theta[b0 + i] + theta[b1 + i]
            j += 2
        else:
            for i in range(db):
                acc[i] += theta[b0 + i]
            j += 1
