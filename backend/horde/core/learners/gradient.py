"""GQ(lambda), GTD(lambda) and off-policy TD(lambda): the gradient-TD family (Maei & Sutton 2010; Maei 2011).

The family shares one trace per class and one pass over its support: GQ learns action values over
state-action features, GTD state values, TD is GTD without the correction and w.

Per demon (`update` below is the readable numpy form; `reference.gq_step`, `gtd_step`, `td_step` the oracle):
    delta_t = r_tp1 + (1 - gamma_tp1) z_tp1 + gamma_tp1 theta . x_bar_tp1 - theta . x_t
    e_t     = x_t + gamma_t lambda rho_t e_{t-1}             (GQ: rho_t weighs the past only)
    e_t     = rho_t (x_t + gamma_t lambda e_{t-1})           (GTD, TD)
    theta  += alpha   (delta_t e_t - gamma_tp1 (1 - lambda) (w . e_t) x_bar_tp1)    (no correction for TD)
    w      += alpha_w (delta_t e_t - (w . x_t) x_t)                                 (GTD and GQ)
GTD(lambda)'s x_bar_tp1 is phi(s_{t+1}). The thesis printed the w update with phi_{t+1} and one shared step
size: both are errors.

The compiled kernel here is GQ's (`prepare`, `columns`, `finish`, called by the engine's step through
`horde.core.learners`; TD's is `td_pass`, GTD's (and TDRC's, GTD2's, the original GTD's) `gtd_pass`, each of
which defers its whole update by one step): `prepare` writes each class's trace decay and what x_t adds, and
merges the traces (`engine.traces.merge`; several classes: `merge_pairs`, two rows at a time; a block where each
demon is its own class, control demons over their own values: only the rows are merged, `traces.union`, and each
demon's trace decays in the support pass, which reads those rows anyway; `finish` keeps the rows left with a
trace as the support); `columns` learns
a run of the block's demons, touching only their columns: each action's rows at s_{t+1} paid and read (four
actions: their rows in one walk, `pay_and_read_four`), w read at x_t, then one pass over the support's weight
rows (each read and written once; rows read two at a time: more memory streams in flight made sparse rows 1.3
to 1.6 times faster; e . x_bar per demon summed in the same loop, `_two_rows`). The correction at x_{t+1} is
owed to the next step (see `columns`), which `settle_owed` pays before anyone else reads theta.

Why one module of about 400 lines: the family's three learners' numpy form and registration, and GQ's kernel.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from horde.core.engine.layout import NO_NRT
from horde.core.engine.rows import at, pay_and_read, pay_and_read_four, spread, square, sum_rows
from horde.core.engine.rows import td_error as td_error_at
from horde.core.engine.traces import decay_classes, decay_two, keep_left, merge, merge_pairs, union
from horde.core.engine.values import observe_range, value_policy
from horde.core.learners.base import Kernel, check, td_error
from horde.core.policies import FIXED
from horde.spec.learners import LearnerInfo, register

GQ = register(LearnerInfo(
    name="gq", text="GQ(λ): action values", paper="Maei & Sutton 2010", action_values=True, secondary=True,
))  # fmt: skip
GTD = register(LearnerInfo(name="gtd", text="GTD(λ): state values", paper="Maei 2011", secondary=True))
TD = register(LearnerInfo(
    name="td", text="TD(λ): state values, no correction", paper="Sutton 1988; off-policy: Precup et al. 2000",
    step_sizes=("constant", "autostep", "tidbd"),
))  # fmt: skip
TD_CODE, GTD_CODE, GQ_CODE = 0, 1, 2  # the engine's kernel codes
KERNELS = (
    Kernel(TD_CODE, "td"),
    Kernel(GTD_CODE, "gtd", vectors=2, owes=True),
    Kernel(GQ_CODE, "gq", vectors=2, owes=True, corrects_every_action=True),
)


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
        check(name, array, (num_demons,))
    check("rho_t", rho_t, (num_demons,))
    check("x_t values", val, idx.shape)

    delta = td_error(r_tp1, z_tp1, gamma_tp1, dot_sparse(theta, bar_idx, bar_val), dot_sparse(theta, idx, val))  # [D]
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


# ----------------------------------------------------------------------------------------------
# The compiled kernel


@njit(**NO_NRT, inline="always")
def prepare(b, lay, wts, dem, cls, stp, scr):
    """Block b's traces for this step (nothing per demon): each class decays by gamma_t lambda rho_t, x_t (of the
    action taken) adds 1; then `merge`. Several classes: x_bar's rows at s_{t+1} (every action's block) are
    marked with x_tp1's values, for the support pass (`columns`)."""
    lo, ncls, coff = lay.block_lo[b], lay.ncls[b], lay.coff[b]
    own = lay.policy[b] != FIXED
    for c in range(ncls):
        rho = dem.pi[lo + c, stp.action] / stp.b_prob if own else cls.rho[coff + c]
        scr.decay[c] = cls.gamma[coff + c] * lay.lam[b] * rho
        scr.add[c] = 1.0
    if ncls > 1 and own:  # each demon its own class: its trace decays in the support pass, where it is read anyway
        kept, dropped = union(b, lay, wts, scr, stp.x_t, stp.v_t, stp.action * stp.n_s), 0
    elif ncls > 1:  # (rows of many classes: two at a time, `merge_pairs`)
        kept, dropped = merge_pairs(b, lay, wts, scr, stp.x_t, stp.v_t, stp.action * stp.n_s, True)
    else:
        kept, dropped = merge(b, lay, wts, scr, stp.x_t, stp.v_t, stp.action * stp.n_s, True)
    scr.counts[0] = kept
    scr.counts[1] = dropped
    if ncls > 1:
        for a in range(lay.actions[b]):
            for j in range(stp.x_tp1.shape[0]):
                scr.mark[a * stp.n_s + stp.x_tp1[j]] = stp.v_tp1[j]


@njit(**NO_NRT, inline="always")
def finish(b, lay, wts, cls, stp, scr):
    """After every column learned: an own-value block's support keeps the rows its pass left with a trace; the
    marks cleared; each class's continuation moves to s_{t+1}."""
    if lay.ncls[b] > 1 and lay.policy[b] != FIXED:
        keep_left(b, lay, wts, scr, scr.counts[0])
    if lay.ncls[b] > 1:
        for a in range(lay.actions[b]):
            for j in range(stp.x_tp1.shape[0]):
                scr.mark[a * stp.n_s + stp.x_tp1[j]] = 0.0
    coff = lay.coff[b]
    for c in range(lay.ncls[b]):
        cls.gamma[coff + c] = cls.gamma_tp1[coff + c]


@njit(**NO_NRT)
def columns(b, i0, i1, lay, wts, dem, cls, stp, scr):
    """Block b's GQ demons i0 <= i < i1 learn the transition, after `prepare`: only their columns of the weights
    and of the per-demon scratch (values, pi_next, work, ex, ev) are touched. Four parts, in this order
    (`benchmarks.gq_parts` times each where it runs).

    The gradient correction at x_{t+1} (theta -= alpha gamma (1 - lambda) (w . e) x_bar_{t+1}, on every action's
    rows, weighted by the target policy there) is owed rather than applied: `owed[a, d]` holds it, and the next
    step pays it on its x_t's rows (the same rows) while it reads its values at x_{t+1} (the other actions'
    rows are in no support). The new values at s_{t+1} then come from the update's algebra instead of a pass
    that corrects and reads those rows again: theta' . x = theta . x + alpha delta (e . x) - owed (x . x), with
    e . x one sum per action (one class) or per demon from the support pass (`mark`, `ex`)."""
    values_and_errors(b, i0, i1, lay, wts, dem, cls, stp, scr)
    step_x = w_at_x(b, i0, i1, lay, wts, dem, stp, scr)
    if lay.ncls[b] == 1:
        _one_class_pass(b, i0, i1, lay, wts, scr, step_x)
    else:
        _classes_pass(b, i0, i1, lay, wts, stp, scr, step_x, lay.policy[b] != FIXED)
    new_values(b, i0, i1, lay, wts, dem, cls, stp, scr)


@njit(**NO_NRT, inline="always")
def values_and_errors(b, i0, i1, lay, wts, dem, cls, stp, scr):
    """Values at s_{t+1} under the weights before this update (the last correction paid), the target policy
    there, delta."""
    lo, woff = lay.block_lo[b], lay.woff[b]
    x_t, v_t, x_tp1, v_tp1, n_s = stp.x_t, stp.v_t, stp.x_tp1, stp.v_tp1, stp.n_s
    theta, owed = wts.theta, wts.owed
    values, pi_next, ex = scr.values, scr.pi_next, scr.ex
    ad, awd, w_dot_e, w_dot_x = scr.work[0], scr.work[1], scr.work[2], scr.work[3]
    db = lay.block_hi[b] - lo
    own = lay.policy[b] != FIXED
    A = dem.q.shape[1]
    if lay.actions[b] == 4:  # (the four actions' rows in one walk: four memory streams at once)
        o = lo + i0
        pay_and_read_four(theta, woff + i0, n_s * db, x_t, v_t, x_tp1, v_tp1, db,
                          (owed[0, o : lo + i1], owed[1, o : lo + i1], owed[2, o : lo + i1], owed[3, o : lo + i1]),
                          (values[0, i0:i1], values[1, i0:i1], values[2, i0:i1], values[3, i0:i1]))  # fmt: skip
    else:
        for a in range(lay.actions[b]):
            pay_and_read(theta, woff + a * n_s * db + i0, x_t, v_t, x_tp1, v_tp1, db, owed[a, lo + i0 : lo + i1],
                         values[a, i0:i1])  # fmt: skip
    for a in range(lay.actions[b]):
        for i in range(i0, i1):
            ex[a, i] = 0.0
    for i in range(i0, i1):
        d = lo + i
        g1 = cls.gamma_tp1[lay.slot_class[d]]
        if own:
            value_policy(lay.policy[b], values[:, i], lay.temperature[d], lay.epsilon[d], pi_next[:, i])
        else:
            for a in range(A):
                pi_next[a, i] = cls.pi_given[lay.slot_class[d], a]
        v_next = 0.0
        for a in range(A):
            v_next += pi_next[a, i] * values[a, i]
        dl = td_error_at(dem.r[d], dem.z[d], g1, v_next, dem.q[d, stp.action])
        dem.delta[d] = dl
        # a frozen demon (step size 0) stays exactly as it is, even when its delta is not finite
        ad[i] = dem.alpha[d] * dl if dem.alpha[d] != 0.0 else 0.0
        awd[i] = dem.alpha_w[d] * dl if dem.alpha_w[d] != 0.0 else 0.0
        w_dot_e[i] = 0.0
        w_dot_x[i] = 0.0


@njit(**NO_NRT, inline="always")
def w_at_x(b, i0, i1, lay, wts, dem, stp, scr):
    """alpha_w (w . x_t) under the old w (returned: the demons' run of scr.work[3]); the rows of x_t left without a
    trace lose it here."""
    lo, woff = lay.block_lo[b], lay.woff[b]
    db = lay.block_hi[b] - lo
    width = i1 - i0
    w, rows, rows_f, dropped = wts.w, scr.rows, scr.rows_f, scr.counts[1]
    step_x = scr.work[3][i0:i1]
    sum_rows(w, woff + stp.action * stp.n_s * db + i0, stp.x_t, stp.v_t, db, step_x)
    for i in range(width):
        a_w = dem.alpha_w[lo + i0 + i]
        step_x[i] = step_x[i] * a_w if a_w != 0.0 else 0.0
    end = rows.shape[0] - 1
    for j in range(dropped):
        start = at(woff + rows[end - j] * db + i0)
        f = rows_f[end - j]
        for i in range(width):
            w[start + at(i)] -= f * step_x[i]
    return step_x


@njit(**NO_NRT, inline="always")
def new_values(b, i0, i1, lay, wts, dem, cls, stp, scr):
    """The correction at x_bar_{t+1} (owed: see `columns`) and the new values at s_{t+1}, for each action's rows
    there; e . x_bar(s_{t+1}, a) from the support pass (`gather`; one class: one sum per action)."""
    lo, voff, ncls = lay.block_lo[b], lay.voff[b], lay.ncls[b]
    x_tp1, v_tp1, n_s = stp.x_tp1, stp.v_tp1, stp.n_s
    trace, owed = wts.trace, wts.owed
    values, pi_next, ex = scr.values, scr.pi_next, scr.ex
    ad, w_dot_e = scr.work[0], scr.work[2]
    for i in range(i0, i1):
        a_i = dem.alpha[lo + i]
        g1 = cls.gamma_tp1[lay.slot_class[lo + i]]
        w_dot_e[i] = a_i * g1 * (1.0 - lay.lam[b]) * w_dot_e[i] if a_i != 0.0 else 0.0
    own_dot = square(v_tp1)
    for a in range(lay.actions[b]):
        if ncls == 1:
            e_dot_x = 0.0
            for j in range(x_tp1.shape[0]):
                e_dot_x += v_tp1[j] * np.float64(trace[voff + a * n_s + x_tp1[j]])
            for i in range(i0, i1):
                ex[a, i] = e_dot_x
        for i in range(i0, i1):
            o = w_dot_e[i] * pi_next[a, i]
            values[a, i] += ad[i] * ex[a, i] - o * own_dot
            owed[a, lo + i] = o
    observe_range(b, i0, i1, lay, dem, cls, values)


@njit(**NO_NRT)
def _one_class_pass(b, i0, i1, lay, wts, scr, step_x):
    """The weight pass of a one-class block over its support, in row order, two rows at a time: theta += ad e;
    w . e, w += awd e - f step_x (f: x_t's value on the row, e the class's trace)."""
    lo, woff = lay.block_lo[b], lay.woff[b]
    db = lay.block_hi[b] - lo
    theta, w = wts.theta, wts.w
    rows, rows_e, rows_f, kept = scr.rows, scr.rows_e, scr.rows_f, scr.counts[0]
    ad, awd, w_dot_e = scr.work[0], scr.work[1], scr.work[2]
    width = i1 - i0
    s = 0
    while s < kept:
        e0 = rows_e[s]
        f0 = rows_f[s]
        u0 = at(woff + rows[s] * db + i0)
        if s + 1 < kept:
            e1 = rows_e[s + 1]
            f1 = rows_f[s + 1]
            u1 = at(woff + rows[s + 1] * db + i0)
            for i in range(width):
                a = ad[i0 + i]
                aw = awd[i0 + i]
                sx = step_x[i]
                j0 = u0 + at(i)
                j1 = u1 + at(i)
                v0 = w[j0]
                v1 = w[j1]
                w_dot_e[i0 + i] += v0 * e0 + v1 * e1
                theta[j0] += a * e0
                theta[j1] += a * e1
                w[j0] = v0 + aw * e0 - f0 * sx
                w[j1] = v1 + aw * e1 - f1 * sx
            s += 2
        else:  # the last row alone
            for i in range(width):
                j0 = u0 + at(i)
                wv = w[j0]
                w_dot_e[i0 + i] += wv * e0
                theta[j0] += ad[i0 + i] * e0
                w[j0] = wv + awd[i0 + i] * e0 - f0 * step_x[i]
            s += 1


@njit(**NO_NRT)
def _classes_pass(b, i0, i1, lay, wts, stp, scr, step_x, own):
    """The weight pass of a block of several classes: each support row's trace values spread over the classes'
    demons (own-value blocks: the trace row itself), two rows at a time; e . x_bar gathered per demon in the same
    loop where the two rows' marks fall on one action's row of `ex` (`_two_rows`), else after it (`_gather`)."""
    lo, woff, voff, ncls, coff = lay.block_lo[b], lay.woff[b], lay.voff[b], lay.ncls[b], lay.coff[b]
    db = lay.block_hi[b] - lo
    width = i1 - i0
    n_s = stp.n_s
    theta, w, trace, mark, ex = wts.theta, wts.w, wts.trace, scr.mark, scr.ex
    rows, rows_f, left, kept = scr.rows, scr.rows_f, scr.rows_left, scr.counts[0]
    decay, add, cut = scr.decay[i0:i1], scr.add[i0:i1], lay.cut
    ad, awd, dot_e = scr.work[0, i0:i1], scr.work[1, i0:i1], scr.work[2, i0:i1]
    e0 = scr.ev[0, i0:i1]
    e1 = scr.ev[1, i0:i1]
    s = 0
    while s < kept:
        pair = s + 1 < kept
        r0 = rows[s]
        r1 = rows[s + 1] if pair else r0
        f0 = rows_f[s]
        f1 = rows_f[s + 1] if pair else 0.0
        if own:
            # The demons' own traces (class i is demon i) decay here, their columns of the two rows, while the
            # rows are in cache: no merge pass over them (`prepare`). Each thread marks the rows its demons left
            # with a trace (only ever a 1: the threads' marks agree), and `finish` keeps those as the support.
            e0 = trace[voff + r0 * ncls + i0 : voff + r0 * ncls + i1]
            e1 = trace[voff + r1 * ncls + i0 : voff + r1 * ncls + i1]
            if pair:
                on_x = (1 if f0 != 0.0 else 0) + (2 if f1 != 0.0 else 0)
                left0, left1 = decay_two(e0, e1, on_x, decay, add, cut, f0, f1)
                if left1:
                    left[s + 1] = 1
            else:
                left0 = decay_classes(e0, f0 != 0.0, decay, add, cut, f0)
            if left0:
                left[s] = 1
        else:
            spread(trace, voff + r0 * ncls, ncls, lay.class_lo, lay.class_hi, coff, i0, i1, e0)
            if pair:
                spread(trace, voff + r1 * ncls, ncls, lay.class_lo, lay.class_hi, coff, i0, i1, e1)
        u0 = at(woff + r0 * db + i0)
        u1 = at(woff + r1 * db + i0)
        if pair:
            g0 = mark[r0]
            g1 = mark[r1]
            x0 = ex[r0 // n_s, i0:i1]
            x1 = ex[r1 // n_s, i0:i1]
            # (the second row's mark first: the order of the sums, as before the engine's layout changed)
            if g0 == 0.0 and g1 == 0.0:
                _two_rows(theta, w, (e0, e1), (u0, u1), (f0, f1), ad, awd, step_x, dot_e, x0, (g0, g1), NO_MARK)
            elif g1 == 0.0:
                _two_rows(theta, w, (e0, e1), (u0, u1), (f0, f1), ad, awd, step_x, dot_e, x0, (g0, g1), FIRST_MARKED)
            elif g0 == 0.0:
                _two_rows(theta, w, (e0, e1), (u0, u1), (f0, f1), ad, awd, step_x, dot_e, x1, (g0, g1), SECOND_MARKED)
            elif r0 // n_s == r1 // n_s:
                _two_rows(theta, w, (e0, e1), (u0, u1), (f0, f1), ad, awd, step_x, dot_e, x0, (g0, g1), BOTH_MARKED)
            else:  # (two actions' rows: at most once an action's block a step)
                _two_rows(theta, w, (e0, e1), (u0, u1), (f0, f1), ad, awd, step_x, dot_e, x0, (g0, g1), NO_MARK)
                _gather(mark, r1, n_s, e1, ex, i0)
                _gather(mark, r0, n_s, e0, ex, i0)
        else:
            for i in range(width):
                a0 = np.float64(e0[i])
                j0 = u0 + at(i)
                v0 = w[j0]
                dot_e[i] += v0 * a0
                theta[j0] += ad[i] * a0
                w[j0] = v0 + awd[i] * a0 - f0 * step_x[i]
            _gather(mark, r0, n_s, e0, ex, i0)
        s += 2 if pair else 1


NO_MARK, FIRST_MARKED, SECOND_MARKED, BOTH_MARKED = 0, 1, 2, 3  # `_two_rows`: which rows add to e . x_bar


@njit(**NO_NRT, inline="always")
def _two_rows(theta, w, traces, starts, xs, ad, awd, step_x, dot_e, ex_a, marks, marked):
    """Two support rows' update (each a pair: their trace values e0, e1 over the demons, their starts u0, u1 in
    theta and w, x_t's values f0, f1 there): theta at u0, u1 += ad e; w . e; w += awd e - f step_x. And, as
    `marked` says (a constant at each call, so that each call's loop is its own), e . x_bar's sums on one action's
    row ex_a (the rows' marks g0, g1): the first row's (g0 e0), the second's (g1 e1), or both, the second first."""
    e0, e1 = traces
    u0, u1 = starts
    f0, f1 = xs
    g0, g1 = marks
    for i in range(dot_e.shape[0]):
        a = ad[i]
        aw = awd[i]
        sx = step_x[i]
        a0 = np.float64(e0[i])
        a1 = np.float64(e1[i])
        j0 = u0 + at(i)
        j1 = u1 + at(i)
        v0 = w[j0]
        v1 = w[j1]
        dot_e[i] += v0 * a0 + v1 * a1
        theta[j0] += a * a0
        theta[j1] += a * a1
        w[j0] = v0 + aw * a0 - f0 * sx
        w[j1] = v1 + aw * a1 - f1 * sx
        if marked == FIRST_MARKED:
            ex_a[i] += g0 * a0
        elif marked == SECOND_MARKED:
            ex_a[i] += g1 * a1
        elif marked == BOTH_MARKED:
            ex_a[i] = (ex_a[i] + g1 * a1) + g0 * a0


@njit(**NO_NRT)
def _gather(mark, row, n_s, e, ex, i0):
    """ex[a, i0 + i] += e[i] times x_bar's value on the support row `row` at s_{t+1} for action a (`mark`)."""
    m = mark[row]
    if m != 0.0:
        ex_a = ex[row // n_s]
        for i in range(e.shape[0]):  # (a row view and unsigned offsets: the loop vectorizes, `rows.at`)
            ex_a[at(i0 + i)] += m * np.float64(e[i])


@njit(**NO_NRT)
def settle_owed(b, lay, wts, x, v, n_s):
    """Pay block b's owed gradient correction (`columns`) on the rows x it is owed on (values v; each action's,
    for action values), and owe nothing more."""
    lo, woff = lay.block_lo[b], lay.woff[b]
    db = lay.block_hi[b] - lo
    theta, owed = wts.theta, wts.owed
    for a in range(lay.actions[b]):
        for j in range(x.shape[0]):
            u = at(woff + (a * n_s + x[j]) * db)
            value = v[j]
            for i in range(db):
                theta[u + at(i)] -= value * owed[a, lo + i]
        for i in range(db):
            owed[a, lo + i] = 0.0
