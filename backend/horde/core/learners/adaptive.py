"""TD(lambda) with a step size per weight, adapted online: TIDBD(lambda) and Autostep (AutoTIDBD).

TIDBD(lambda) (Kearney, Veeriah, Travnik, Pilarski & Sutton 2019) and Autostep (Mahmood, Sutton, Degris &
Pilarski 2012) in its TD form (AutoTIDBD, Kearney et al. 2019): step-size modes of the `td` learner
(`step_size = "tidbd" | "autostep"`). Readable numpy form below (`adaptive_td_update`);
`reference.adaptive_td_step` is the oracle.

The compiled kernel keeps TD's shared trace and adds, per demon and weight, a step size (`Online.step_a`,
times a per-demon scale `Online.scale`, so that Autostep's division of every step size by M costs O(1)),
its h (in the block's w, which TD leaves unused) and, for Autostep, its normaliser v (`Online.step_v`).
Feature values enter where the papers' phi_i does: the meta-gradient sample delta phi_i h_i, Autostep's
normaliser step alpha_i phi_i e_i, the effective step size alpha . e (phi - gamma phi'), h's decay
[1 - alpha_i phi_i e_i]^+.

A step is three passes over few rows: the values at x_tp1 under the weights before the step (on the threads;
from each demon's value at x_t and the few rows where x_tp1 differs from x_t, `online.values_at_next`; then the
TD errors); the meta step on the rows of x_t only (phi_i = 0 elsewhere: the papers' update
leaves alpha_i and v_i of other weights as they are); theta and h on the support's rows (every weight with a
nonzero trace), fused with reading the new values at x_tp1. Autostep's effective step size is summed within
the first two passes. The paper's order divides every step size by M, a sum over all the rows of x_t, before
theta moves; for TIDBD, which has no M, and for a run of Autostep demons whose M provably stays 1 (an upper
bound from each demon's largest step size, `Online.step_max`, which the kernels keep as they move step sizes,
as |the meta step's argument| <= mu) the meta step and the update go in one walk (`fused_columns`, the same
operations in the same order: the same numbers). Autostep's exp is a polynomial when the block's meta step
sizes allow (`exp_tiny`, `exp_small`), chosen once per block, and `engine.fast_exp.vector_exp` otherwise (an exp
whose loops vectorize: `math.exp` is a call per weight); `_adaptive_kernel` compiles the kernel once per kind of
exp. TIDBD's walk takes `exp_small`: the few demons whose arguments may reach beyond 1/16 (each demon's largest
|phi h| over x_t's rows, which the last step's walk read over x_tp1's, `Online.w_read[0]`) take their meta steps
apart with `vector_exp` before it (`large_meta_steps`).

Why one module of about 550 lines: the kernel factory is the three passes written once, with their numpy form
and registration beside them, and TIDBD's meta steps taken apart.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from horde.core.engine.fast_exp import INVERSE_FACTORIAL, TAYLOR, fma, taylor, vector_exp
from horde.core.engine.layout import NO_NRT
from horde.core.engine.rows import add_row, at, walk
from horde.core.engine.traces import merge
from horde.core.learners.base import Kernel, OnlineState, check_online, target
from horde.core.learners.online import class_bounds, errors, store_values, values_at_next

TIDBD_CODE, AUTOSTEP_CODE = 6, 7  # the engine's kernel codes
KERNELS = (
    Kernel(TIDBD_CODE, "td", step_size="tidbd", vectors=3, keeps_state=True),
    Kernel(AUTOSTEP_CODE, "td", step_size="autostep", vectors=4, keeps_state=True),
)
TINY_EXP = 0.01  # Autostep's meta steps with mu at most this use exp_tiny (|argument| <= mu), the default mu
SMALL_EXP = 1.0 / 16  # ... with mu at most this exp_small, above it `vector_exp`
EXP_ANY, EXP_SMALL, EXP_TINY = 0, 1, 2  # which exp a block's meta steps take (`prepare`)
SCALE_FLOOR = 1e-150  # a demon's lazily kept step-size scale is folded back into its step sizes below this


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
    check_online(state, x_t, lam, autostep, meta, r_tp1, z_tp1, gamma_t, gamma_tp1, rho_t)
    _, _, delta = target(state, x_t, x_tp1, r_tp1, z_tp1, gamma_tp1)
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


# ----------------------------------------------------------------------------------------------
# The compiled kernel


@njit(**NO_NRT)
def prepare(code, b, lay, wts, cls, onl, stp, scr):
    """Block b before its columns: each class's trace decays by gamma_t lambda rho_t and x_t adds rho_t (TD's
    trace); the block's meta step sizes choose the kind of exp (in scr.counts[1])."""
    lo, ncls, coff = lay.block_lo[b], lay.ncls[b], lay.coff[b]
    for c in range(ncls):
        rho = cls.rho[coff + c]
        scr.decay[c] = cls.gamma[coff + c] * lay.lam[b] * rho
        scr.add[c] = rho
    class_bounds(b, lay, onl)
    if code == TIDBD_CODE and onl.w_read_ok[b] == 0:
        count_largest_products(b, lay, wts, onl, stp.x_t, stp.v_t)
        onl.w_read_ok[b] = 1
    kept, _ = merge(b, lay, wts, scr, stp.x_t, stp.v_t, 0, False)
    scr.counts[0] = kept
    bound = 0.0  # the largest meta step size of the block: which exp its meta steps take (one kind for the block)
    for i in range(lay.block_hi[b] - lo if code == AUTOSTEP_CODE else 0):
        bound = max(bound, onl.meta[lo + i])
    scr.counts[1] = exp_kind(bound)


@njit(**NO_NRT)
def exp_kind(bound):
    """Which exp Autostep's meta steps take when no meta step size of the block is above `bound` (|the
    argument| <= mu, as |delta phi h| <= v)."""
    return EXP_TINY if bound <= TINY_EXP else (EXP_SMALL if bound <= SMALL_EXP else EXP_ANY)


@njit(**NO_NRT)
def columns(code, b, i0, i1, lay, wts, dem, cls, onl, stp, scr):
    """Block b's demons i0 <= i < i1 learn the transition with the kind of exp `prepare` chose."""
    kind = scr.counts[1]
    if code == TIDBD_CODE:
        _tidbd(b, i0, i1, lay, wts, dem, cls, onl, stp, scr)
    elif kind == EXP_TINY:
        _autostep_tiny(b, i0, i1, lay, wts, dem, cls, onl, stp, scr)
    elif kind == EXP_SMALL:
        _autostep_small(b, i0, i1, lay, wts, dem, cls, onl, stp, scr)
    else:
        _autostep_any(b, i0, i1, lay, wts, dem, cls, onl, stp, scr)
    store_values(b, i0, i1, lay, dem, scr)


def _adaptive_kernel(exp, autostep):
    """Autostep (`autostep`) or TIDBD for TD(lambda) (reference.adaptive_td_step), compiled once per kind of exp
    for Autostep's meta step (`exp`: `exp_tiny`, `exp_small` or `vector_exp`; chosen once per block by
    `prepare`) and once for TIDBD, so that the source is written once and each hot loop has one kind of exp and
    one learner (a flag read at run time inside a loop kept it from vectorizing).

    Why about 170 lines: the factory is the compiled kernels themselves (the meta step, the fused walk and
    the two-pass columns, each short): they are closures over `exp`, so that numba binds the exp when it
    compiles them, and closures must be written inside the function that makes them."""
    # (`exp` and `autostep` are constants to numba: the branches on `autostep` below are compiled away)

    @njit(inline="always")
    def meta_step(at_, u, d, e, p, inv_tau, a, v, h, demons):
        """The meta step of weight at_ (column u, demon d; x_t's value p there) from h_i as it was, Autostep's:
        v_i, then the argument of exp (|sample| <= v_i), then alpha_i, and the demon's largest step size kept
        (`Online.step_max`); TIDBD's: alpha_i *= exp(mu delta phi_i h_i). Returns the new alpha_i. (`demons`, the
        per-demon arrays, is one tuple built before the loops: built per weight, it slowed the walk by 2 %.)"""
        meta, rate, dlv, largest = demons
        if not autostep:  # (TIDBD's meta is per column: 0 where `large_meta_steps` took the demon's meta steps)
            a[at_] *= exp(meta[u] * dlv[u] * p * h[at_])
            return a[at_]
        sample = dlv[u] * p * h[at_]
        size = abs(sample)
        vi = max(size, v[at_] + a[at_] * rate[u] * e * p * (size - v[at_]) * inv_tau)
        v[at_] = vi
        a[at_] *= exp(meta[d] * (sample / vi if vi > 0.0 else 0.0))
        # fmax, not max: LLVM turns `largest[d] = max(largest[d], x)` into a masked store (vmaskmovpd), which AMD's
        # Zen cores run slowly (the fused walk took 1.3 times as long); the same number, as largest is never NaN
        largest[d] = np.fmax(largest[d], a[at_])
        return a[at_]

    @njit(inline="always")
    def learn_weight(k, u, d, e, p, inv_tau, vectors, demons):
        """One weight k of a row of x_t (x_t's value p there; column u, demon d): its meta step, then theta +=
        alpha delta e and h = h [1 - alpha phi e]^+ + alpha delta e from h as the meta step read it."""
        theta, h, a, v = vectors
        rate, dlv = demons[1], demons[2]
        h_i = h[k]
        size = meta_step(k, u, d, e, p, inv_tau, a, v, h, demons)
        step = size * rate[u] * e
        change = step * dlv[u]
        theta[k] += change
        h[k] = h_i * max(1.0 - step * p, 0.0) + change

    @njit
    def fused_columns(b, i0, i1, lay, wts, onl, stp, scr):
        """The meta step and the update in one walk over the rows of the support, x_t and x_tp1, for TIDBD and for
        a run of Autostep demons none of which has M > 1: on a row of x_t each weight's meta step, then at once
        its theta and h (theta += alpha delta e; h = h [1 - alpha phi e]^+ + alpha delta e, from h as the meta
        step read it), the same operations in the same order as the two passes, so the same numbers; eight
        numbers per weight of x_t read or written instead of ten. The new values at x_tp1 take each row right
        after it moved, on a row of x_t in the same loop (the weight as stored)."""
        lo, woff, voff, ncls = lay.block_lo[b], lay.woff[b], lay.voff[b], lay.ncls[b]
        db = lay.block_hi[b] - lo
        theta, h, trace, rows, kept = wts.theta, wts.w, wts.trace, scr.rows, scr.counts[0]
        a, v, meta, bounds, inv_tau = onl.step_a, onl.step_v, onl.meta, onl.bounds, 1.0 / onl.tau
        rate, dlv, acc, largest = scr.work[5], scr.work[6], scr.values[0], onl.step_max
        x_t, v_t, x_tp1, v_tp1 = stp.x_t, stp.v_t, stp.x_tp1, stp.v_tp1
        vectors, demons = (theta, h, a, v), (meta if autostep else scr.work[0], rate, dlv, largest)
        next_h = scr.work[1]  # TIDBD: each demon's largest |phi' h| over x_tp1's rows, for the next step's exp
        s = j = m = 0  # positions in the support, x_t and x_tp1
        while True:
            row, in_support, on_x, on_next, s, j, m = walk(rows, kept, s, x_t, v_t, j, x_tp1, v_tp1, m)
            if row < 0:
                break
            base = at(woff + row * db)
            tr = voff + row * ncls
            learned = on_x != 0.0 or in_support
            for c in range(ncls if learned else 0):
                c0, c1 = max(bounds[c], i0), min(bounds[c + 1], i1)
                e = trace[tr + c]
                if on_x != 0.0 and e != 0.0 and on_next != 0.0:  # x_tp1's value read from the weight just moved
                    for i in range(c0, c1):
                        u = at(i)
                        learn_weight(base + u, u, at(lo + i), e, on_x, inv_tau, vectors, demons)
                        acc[u] += on_next * theta[base + u]  # (as stored: float32 rounds before it is read)
                        if not autostep:
                            next_h[u] = np.fmax(next_h[u], abs(on_next * h[base + u]))  # (`largest_product`)
                    continue
                if on_x != 0.0 and e != 0.0:
                    for i in range(c0, c1):
                        u = at(i)
                        learn_weight(base + u, u, at(lo + i), e, on_x, inv_tau, vectors, demons)
                elif on_x != 0.0:  # a row of x_t whose trace was cut: the meta step only
                    for i in range(c0, c1):
                        u = at(i)
                        meta_step(base + u, u, at(lo + i), e, on_x, inv_tau, a, v, h, demons)
                elif e != 0.0:
                    _trace_update(c0, c1, base, e, a, rate, dlv, theta, h)
                if on_next != 0.0:
                    add_row(c0, c1, base, theta, acc, on_next)
                    if not autostep:
                        largest_product(c0, c1, base, h, on_next, next_h)
            if on_next != 0.0 and not learned:
                add_row(i0, i1, base, theta, acc, on_next)
                if not autostep:
                    largest_product(i0, i1, base, h, on_next, next_h)

    @njit
    def _meta_steps(b, i0, i1, lay, wts, cls, onl, stp, scr):
        """Autostep's meta step on the rows of x_t (where phi_i != 0): alpha_i *= exp(meta delta phi_i h_i / v_i),
        alpha_i e_i (phi_i - gamma_tp1 phi'_i) added to the effective step size there; then every step size
        divided by M = max(1, the effective step size). A scale below SCALE_FLOOR is folded back."""
        lo, woff, voff, ncls, coff = lay.block_lo[b], lay.woff[b], lay.voff[b], lay.ncls[b], lay.coff[b]
        db = lay.block_hi[b] - lo
        h, trace = wts.w, wts.trace
        a, v, scale, meta, bounds, inv_tau = onl.step_a, onl.step_v, onl.scale, onl.meta, onl.bounds, 1.0 / onl.tau
        rate, dlv, effective, largest = scr.work[5], scr.work[6], scr.work[7], onl.step_max
        demons = (meta, rate, dlv, largest)
        x_t, v_t, x_tp1, v_tp1 = stp.x_t, stp.v_t, stp.x_tp1, stp.v_tp1
        m = 0
        for j in range(x_t.shape[0]):
            row = x_t[j]
            p = v_t[j]
            base = at(woff + row * db)
            tr = voff + row * ncls
            while m < x_tp1.shape[0] and x_tp1[m] < row:
                m += 1
            on_next = v_tp1[m] if m < x_tp1.shape[0] and x_tp1[m] == row else 0.0
            for c in range(ncls):
                c0, c1 = max(bounds[c], i0), min(bounds[c + 1], i1)
                e = trace[tr + c]
                coeff = e * (p - cls.gamma_tp1[coff + c] * on_next)
                for i in range(c0, c1):
                    u = at(i)
                    size = meta_step(base + u, u, at(lo + i), e, p, inv_tau, a, v, h, demons)
                    effective[u] += size * coeff
        for i in range(i0, i1):  # every step size divided by M = max(1, the effective step size)
            m_i = effective[i] * rate[i]
            if m_i > 1.0:
                scale[lo + i] /= m_i
                rate[i] /= m_i
        for i in range(i0, i1):
            if scale[lo + i] < SCALE_FLOOR:
                _fold_scale(a, scale, largest, woff, db, i, lo + i, woff + lay.rows[b] * db)
                rate[i] = 1.0 if rate[i] != 0.0 else 0.0  # (0 where frozen)

    @njit
    def adaptive_columns(b, i0, i1, lay, wts, dem, cls, onl, stp, scr):
        """Columns i0 <= i < i1 of a TIDBD / Autostep block; h lives in w.

        Each class's demons in one contiguous, branch-free run (feature-major, as the other kernels): a
        frozen demon enters with rate 0 and delta 0, which leaves its weights, h, v and step sizes as they
        are. First the values at x_tp1 under the weights before the step (`values_at_next`: from the values at x_t
        and the few rows where x_tp1 differs), then the TD errors; then either
        the meta step on the rows of x_t and the update over the support fused with reading the new values
        at x_tp1, or, for TIDBD and when no Autostep demon of the run can have M > 1, both in one walk
        (`fused_columns`). Autostep's effective step size alpha . e (x_t - gamma x_tp1) is summed on a row of
        x_tp1 alone (whose step sizes do not move) before the TD errors, on a row of x_t after its step sizes
        moved.
        """
        lo, woff, voff, ncls, coff = lay.block_lo[b], lay.woff[b], lay.voff[b], lay.ncls[b], lay.coff[b]
        db = lay.block_hi[b] - lo
        trace = wts.trace
        a, meta, bounds, largest = onl.step_a, onl.meta, onl.bounds, onl.step_max
        rate, effective, acc = scr.work[5], scr.work[7], scr.values[0]
        x_t, v_t, x_tp1, v_tp1 = stp.x_t, stp.v_t, stp.x_tp1, stp.v_tp1
        values_at_next(b, i0, i1, lay, wts, dem, stp, acc)
        for i in range(i0, i1):
            effective[i] = 0.0
        # Autostep: the effective step size on the rows of x_tp1 alone (their step sizes do not move; the rows of
        # x_t add theirs after the meta step)
        j = 0
        for m in range(x_tp1.shape[0] if autostep else 0):
            row = x_tp1[m]
            while j < x_t.shape[0] and x_t[j] < row:
                j += 1
            if j < x_t.shape[0] and x_t[j] == row:
                continue
            base = at(woff + row * db)
            for c in range(ncls):
                e = trace[voff + row * ncls + c]
                if e != 0.0:
                    c0, c1 = max(bounds[c], i0), min(bounds[c + 1], i1)
                    _effective_run(c0, c1, base, e * (-cls.gamma_tp1[coff + c] * v_tp1[m]), a, effective)
        errors(b, i0, i1, lay, dem, cls, onl, acc, scr)
        for i in range(i0, i1):
            acc[i] = 0.0  # the new values at x_tp1, summed in the last pass
        # M_i = rate_i alpha . e (x_t - gamma x_tp1) <= rate_i (exp(mu_i) upper_i + max(effective_i, 0)), as
        # |the meta step's argument| <= mu_i, where upper_i = the largest step size of demon i (`Online.step_max`)
        # times sum |e (phi - gamma phi')| over x_t's rows, one sum per class: no step size is read for it. With a
        # margin for the rounding of the sums, no step size of such a demon is divided by M.
        fused = True  # (TIDBD has no M)
        for c in range(ncls if autostep else 0):
            c0, c1 = max(bounds[c], i0), min(bounds[c + 1], i1)
            spread = _spread(voff + c, ncls, trace, cls.gamma_tp1[coff + c], x_t, v_t, x_tp1, v_tp1) if c0 < c1 else 0.0
            for i in range(c0, c1):
                upper = largest[lo + i] * spread
                positive = max(effective[i], 0.0)
                bound = rate[i] * (math.exp(meta[lo + i]) * upper * (1.0 + 1e-9) + positive + abs(effective[i]) * 1e-9)
                fused = fused and bound <= 1.0
        if not autostep:
            large_meta_steps(b, i0, i1, lay, wts, onl, stp, scr)
        if fused:
            fused_columns(b, i0, i1, lay, wts, onl, stp, scr)
            if not autostep:  # TIDBD: what the walk read for the next step
                for i in range(i0, i1):
                    onl.w_read[0, lo + i] = scr.work[1, i]
            return
        _meta_steps(b, i0, i1, lay, wts, cls, onl, stp, scr)
        _update(b, i0, i1, lay, wts, onl, stp, scr)

    return adaptive_columns


@njit(**NO_NRT)
def large_meta_steps(b, i0, i1, lay, wts, onl, stp, scr):
    """TIDBD's meta steps, alpha_i *= exp(mu delta phi_i h_i), taken here with `vector_exp` for block b's demons
    i0 <= i < i1 whose arguments may reach beyond SMALL_EXP on the rows of x_t (about 1 % of the nexting demons,
    spread over the block); the walk's exp, `exp_small`, takes the others'. What decides is each demon's largest
    |phi_i h_i| over x_t's rows (`Online.w_read[0]`, read by the last step's walk or `count_largest_products`),
    one number per demon, so that no weight's number depends on how the columns are split. scr.work[0] becomes
    each column's meta step size for the walk: mu, or 0 where the meta steps were taken here (exp(0) is 1
    exactly); scr.work[1], where the walk keeps the same largest product over x_tp1's rows for the next step,
    starts at 0."""
    lo, woff, db = lay.block_lo[b], lay.woff[b], lay.block_hi[b] - lay.block_lo[b]
    h, a, meta, largest = wts.w, onl.step_a, onl.meta, onl.w_read[0]
    dlv, walk_meta, next_largest = scr.work[6], scr.work[0], scr.work[1]
    x_t, v_t = stp.x_t, stp.v_t
    for i in range(i0, i1):
        next_largest[i] = 0.0
        mu = meta[lo + i]
        if abs(mu * dlv[i]) * largest[lo + i] <= SMALL_EXP:  # (a NaN fails it)
            walk_meta[i] = mu
            continue
        walk_meta[i] = 0.0
        for j in range(x_t.shape[0]):
            k = at(woff + x_t[j] * db + i)
            if v_t[j] != 0.0:  # (as the walk: no meta step where x_t's value is 0)
                a[k] *= vector_exp(mu * dlv[i] * v_t[j] * h[k])


@njit(**NO_NRT)
def count_largest_products(b, lay, wts, onl, x_t, v_t):
    """Each of block b's TIDBD demons' largest |phi_i h_i| over the rows of x_t, read afresh (`large_meta_steps`)
    where the last step's walk did not read it: at the first step, after an episode's start or a load."""
    lo, woff, db = lay.block_lo[b], lay.woff[b], lay.block_hi[b] - lay.block_lo[b]
    largest = onl.w_read[0]
    for i in range(db):
        largest[lo + i] = 0.0
    for j in range(x_t.shape[0]):
        base, p = at(woff + x_t[j] * db), v_t[j]
        for i in range(db if p != 0.0 else 0):
            largest[lo + i] = np.fmax(largest[lo + i], abs(p * wts.w[base + at(i)]))


@njit(**NO_NRT, inline="always")
def largest_product(c0, c1, base, h, value, largest):
    """largest = max(largest, |value h|) over one run of columns of the row at base."""
    for i in range(c0, c1):
        u = at(i)
        largest[u] = np.fmax(largest[u], abs(value * h[base + u]))  # (fmax, not max: see `meta_step`)


@njit(**NO_NRT)
def _update(b, i0, i1, lay, wts, onl, stp, scr):
    """theta += alpha delta e; h = h [1 - alpha phi e]^+ + alpha delta e, over the trace's rows; then the new
    values at x_tp1 from each row right after it moved."""
    lo, woff, voff, ncls = lay.block_lo[b], lay.woff[b], lay.voff[b], lay.ncls[b]
    db = lay.block_hi[b] - lo
    theta, h, trace, rows, kept = wts.theta, wts.w, wts.trace, scr.rows, scr.counts[0]
    a, bounds = onl.step_a, onl.bounds
    rate, dlv, acc = scr.work[5], scr.work[6], scr.values[0]
    x_t, v_t, x_tp1, v_tp1 = stp.x_t, stp.v_t, stp.x_tp1, stp.v_tp1
    s = 0
    j = 0
    m = 0
    while True:
        row = -1
        if s < kept:
            row = rows[s]
        if m < x_tp1.shape[0] and (row < 0 or x_tp1[m] < row):
            row = x_tp1[m]
        if row < 0:
            break
        in_support = s < kept and rows[s] == row
        on_next = m < x_tp1.shape[0] and x_tp1[m] == row
        p_next = v_tp1[m] if on_next else 0.0
        s += 1 if in_support else 0
        m += 1 if on_next else 0
        base = at(woff + row * db)
        if in_support:
            while j < x_t.shape[0] and x_t[j] < row:
                j += 1
            p = v_t[j] if j < x_t.shape[0] and x_t[j] == row else 0.0
            tr = voff + row * ncls
            for c in range(ncls):
                e = trace[tr + c]
                if e == 0.0:
                    continue
                c0 = max(bounds[c], i0)
                c1 = min(bounds[c + 1], i1)
                if p != 0.0:
                    for i in range(c0, c1):
                        u = at(i)
                        k = base + u
                        step = a[k] * rate[u] * e
                        change = step * dlv[u]
                        theta[k] += change
                        h[k] = h[k] * max(1.0 - step * p, 0.0) + change
                else:
                    _trace_update(c0, c1, base, e, a, rate, dlv, theta, h)
        if on_next:
            add_row(i0, i1, base, theta, acc, p_next)


@njit(**NO_NRT, inline="always")
def _trace_update(c0, c1, base, e, a, rate, dlv, theta, h):
    """theta += alpha delta e and h += alpha delta e over one class's run of demons at a row outside x_t."""
    for i in range(c0, c1):
        u = at(i)
        k = base + u
        change = a[k] * rate[u] * e * dlv[u]
        theta[k] += change
        h[k] += change


@njit(**NO_NRT)
def _spread(start, ncls, trace, g, x_t, v_t, x_tp1, v_tp1):
    """sum over the rows of x_t of |e (phi - g phi')|: the trace of one class (its value on row r at start + r ncls)
    times x_t's value less g times x_tp1's there."""
    total = 0.0
    m = 0
    for j in range(x_t.shape[0]):
        row = x_t[j]
        while m < x_tp1.shape[0] and x_tp1[m] < row:
            m += 1
        p_next = v_tp1[m] if m < x_tp1.shape[0] and x_tp1[m] == row else 0.0
        total += abs(trace[start + row * ncls] * (v_t[j] - g * p_next))
    return total


@njit(**NO_NRT, inline="always")
def _effective_run(c0, c1, base, coeff, a, effective):
    """effective += alpha coeff over one class's run of demons at one row (coeff: e (phi - gamma_tp1 phi'))."""
    for i in range(c0, c1):
        u = at(i)
        effective[u] += a[base + u] * coeff


@njit(cache=True, inline="always")
def exp_small(x):
    """exp(x) for |x| <= SMALL_EXP: its Taylor polynomial of degree 9 (the remainder is below 3e-19 relative,
    far under the double's rounding) in fused multiply-adds, fewer than `vector_exp`, which reduces its argument
    first. As `fast_exp.reduced_exp`, 1 + x (1 + x (1/2 + x Q(x))) with the tail Q by Estrin's scheme: six
    operations deep where Horner's rule is nine (TIDBD's walk waits on the chain: 6 % of its step)."""
    c = INVERSE_FACTORIAL
    x2 = x * x
    # (mypy reads an intrinsic as its typing function: the ignore below)
    low: float = fma(fma(c[6], x, c[5]), x2, fma(c[4], x, c[3]))  # type: ignore[call-arg]
    tail = fma(fma(c[9], x, c[8]), x2 * x2 * x, fma(c[7], x2 * x2, low))
    return fma(fma(fma(tail, x, c[2]), x, c[1]), x, c[0])


@njit(cache=True, inline="always")
def exp_tiny(x):
    """exp(x) for |x| <= TINY_EXP: its Taylor polynomial of degree 6 (the remainder is below 2e-18 relative, under
    the double's rounding), three multiply-adds fewer than `exp_small`."""
    return taylor(x, TAYLOR[-7:])


_autostep_tiny = _adaptive_kernel(exp_tiny, True)
_autostep_small = _adaptive_kernel(exp_small, True)
_autostep_any = _adaptive_kernel(vector_exp, True)
_tidbd = _adaptive_kernel(exp_small, False)  # (its demons with larger arguments: `large_meta_steps`)


@njit(**NO_NRT)
def _fold_scale(step_a, scale, largest, woff, db, i, d, end):
    """Multiply demon d's scale into its stored step sizes (column i of the block at woff..end), scale 1; their
    largest counted again from the stored products (float32 may round one above the float64 product)."""
    top = 0.0
    for k in range(woff + i, end, db):
        step_a[k] *= scale[d]
        top = max(top, step_a[k])
    largest[d] = top
    scale[d] = 1.0


@njit(**NO_NRT)
def freeze(b, i, lay, onl):
    """Block b's demon i is frozen: its step sizes 0, its normalisers 0, its scale 1. They may be infinite or NaN
    by now, and the frozen demon's meta steps and updates go on at rate 0 (its TD error 0): a finite step size
    keeps its weights and h at 0 (an infinite one would write inf times 0, a NaN, into them on every step)."""
    if lay.learner[b] != TIDBD_CODE and lay.learner[b] != AUTOSTEP_CODE:
        return
    lo, rows, woff = lay.block_lo[b], lay.rows[b], lay.woff[b]
    db = lay.block_hi[b] - lo
    for row in range(rows):
        onl.step_a[woff + row * db + i] = 0.0
        onl.step_v[woff + row * db + i] = 0.0
    onl.scale[lo + i] = 1.0
    onl.step_max[lo + i] = 0.0


@njit(**NO_NRT)
def reset(lay, onl):
    """An episode starts: adaptive demons that forget their weights (reset = "episode") restart their step
    sizes at alpha and their normalisers at 0, as `reference.ReferenceHorde.observe` does (the engine's
    `observe` zeroes their weights and h)."""
    for b in range(lay.learner.shape[0]):
        if lay.learner[b] != TIDBD_CODE and lay.learner[b] != AUTOSTEP_CODE:
            continue
        lo, rows, woff = lay.block_lo[b], lay.rows[b], lay.woff[b]
        db = lay.block_hi[b] - lo
        for i in range(db):
            if not lay.reset[lo + i]:
                continue
            for row in range(rows):
                onl.step_a[woff + row * db + i] = lay.alpha[lo + i]
                onl.step_v[woff + row * db + i] = 0.0
            onl.scale[lo + i] = 1.0
            onl.step_max[lo + i] = onl.step_a[woff + i] if rows > 0 else 0.0  # alpha as stored (float32 rounds)
