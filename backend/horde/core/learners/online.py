"""What the compiled learners that apply their own update within the step share (true online GTD, the adaptive
step sizes): their classes' runs of demons, the TD errors read before any weight moves, the walk that updates
theta over the trace's rows, and the end of a step. (TD, emphatic TD and true online TD owe their update to the
next step instead: `td_pass`.)

Both read the values at s_{t+1} under the weights before the step (`values_at_next`) from each demon's value at
s_t and the few rows where x_{t+1} differs from x_t. True online GTD reads them before the traces move
(`read_errors`), then walks the rows of the new support, x_t and x_tp1 in increasing order (`dutch_columns`): each
weight row read and written once, the new values at s_{t+1} summed from it right after it moved. Within a row,
class by class, each class's demons in one contiguous run (`Online.bounds`).
"""

from __future__ import annotations

from numba import njit

from horde.core.engine.layout import NO_NRT
from horde.core.engine.rows import add_row, at, td_error, walk


@njit(**NO_NRT)
def class_bounds(b, lay, onl):
    """onl.bounds[c] = the first demon (within block b) of its class c, then Db: the demons of a class are
    consecutive and the classes in order."""
    lo, coff = lay.block_lo[b], lay.coff[b]
    db = lay.block_hi[b] - lo
    onl.bounds[0] = 0
    for i in range(db):
        onl.bounds[lay.slot_class[lo + i] - coff + 1] = i + 1


@njit(**NO_NRT)
def errors(b, i0, i1, lay, dem, cls, onl, v_next, scr):
    """The TD errors of block b's demons i0 <= i < i1 from their values v_next[i] at s_{t+1} under the weights
    before the step; what the weight passes take of them: rate (work[5]: the demon's step-size scale, 0 where
    frozen) and delta where live (work[6]). Each demon's v_old becomes its value at s_{t+1}."""
    lo = lay.block_lo[b]
    rate, dlv = scr.work[5], scr.work[6]
    for i in range(i0, i1):
        d = lo + i
        dl = td_error(dem.r[d], dem.z[d], cls.gamma_tp1[lay.slot_class[d]], v_next[i], dem.q[d, 0])
        dem.delta[d] = dl
        live = dem.alpha[d] != 0.0
        rate[i] = onl.scale[d] if live else 0.0  # a frozen demon moves nothing (rate and delta 0)
        dlv[i] = dl if live else 0.0
        if live:
            onl.v_old[d] = v_next[i]


@njit(**NO_NRT)
def read_errors(b, lay, wts, dem, cls, onl, stp, scr):
    """Block b's values at s_{t+1} before any weight moves (in scr.values[0]) and its TD errors (`errors`)."""
    db = lay.block_hi[b] - lay.block_lo[b]
    v_old = scr.work[3]  # each demon's theta_{t-1} . x_t, kept before `errors` moves v_old on
    for i in range(db):
        v_old[i] = onl.v_old[lay.block_lo[b] + i]
    values_at_next(b, 0, db, lay, wts, dem, stp, scr.values[0])
    errors(b, 0, db, lay, dem, cls, onl, scr.values[0], scr)


@njit(**NO_NRT)
def values_at_next(b, i0, i1, lay, wts, dem, stp, acc):
    """acc[i] = theta . x_tp1 for block b's demons i0 <= i < i1 (state values), the weights before the step: each
    demon's value at s_t (dem.q, theta . x_t, stored by the last step or the episode's start) plus theta times
    x_tp1 - x_t on the rows where they differ, when those are fewer than x_tp1's rows (8 of 457 on a nexting
    step, on average: consecutive states share most tiles); else summed over x_tp1's rows. The choice is the
    block's, from the features alone, so that the numbers do not depend on how its columns are split."""
    lo, woff = lay.block_lo[b], lay.woff[b]
    db = lay.block_hi[b] - lo
    x_t, v_t, x_tp1, v_tp1 = stp.x_t, stp.v_t, stp.x_tp1, stp.v_tp1
    from_x_t = differs_less(x_t, v_t, x_tp1, v_tp1)
    for i in range(i0, i1):
        acc[i] = dem.q[lo + i, 0] if from_x_t else 0.0
    j = 0
    for m in range(x_tp1.shape[0]):
        row = x_tp1[m]
        while from_x_t and j < x_t.shape[0] and x_t[j] < row:  # a row of x_t alone: less its value there
            add_row(i0, i1, at(woff + x_t[j] * db), wts.theta, acc, -v_t[j])
            j += 1
        change = v_tp1[m]
        if from_x_t and j < x_t.shape[0] and x_t[j] == row:
            change -= v_t[j]
            j += 1
        if change != 0.0:
            add_row(i0, i1, at(woff + row * db), wts.theta, acc, change)
    while from_x_t and j < x_t.shape[0]:
        add_row(i0, i1, at(woff + x_t[j] * db), wts.theta, acc, -v_t[j])
        j += 1


@njit(**NO_NRT)
def differs_less(x_t, v_t, x_tp1, v_tp1):
    """Whether fewer rows differ between x_t and x_tp1 (a row in one only, or its value changed) than x_tp1 has."""
    count = 0
    j = 0
    for m in range(x_tp1.shape[0]):
        while j < x_t.shape[0] and x_t[j] < x_tp1[m]:
            count += 1
            j += 1
        if j < x_t.shape[0] and x_t[j] == x_tp1[m]:
            count += 1 if v_t[j] != v_tp1[m] else 0
            j += 1
        else:
            count += 1
    return count + x_t.shape[0] - j < x_tp1.shape[0]


@njit(**NO_NRT)
def dutch_columns(b, i0, i1, lay, wts, stp, scr, onl):
    """theta += coef e over the support, -= x_t's value times fix on the rows of x_t and -= x_tp1's value times
    the correction on the rows of x_tp1, then the new values at x_tp1 for columns i0 <= i < i1 (in
    scr.values[0]). coef is work[0], fix work[1], the correction work[2]."""
    woff, voff, ncls = lay.woff[b], lay.voff[b], lay.ncls[b]
    db = lay.block_hi[b] - lay.block_lo[b]
    theta, trace, rows, kept, bounds = wts.theta, wts.trace, scr.rows, scr.counts[0], onl.bounds
    coef, fix, correction, acc = scr.work[0], scr.work[1], scr.work[2], scr.values[0]
    x_t, v_t, x_tp1, v_tp1 = stp.x_t, stp.v_t, stp.x_tp1, stp.v_tp1
    for i in range(i0, i1):
        acc[i] = 0.0
    s = 0
    j = 0
    m = 0
    while True:
        row, in_support, on_x, on_next, s, j, m = walk(rows, kept, s, x_t, v_t, j, x_tp1, v_tp1, m)
        if row < 0:
            break
        base = at(woff + row * db)
        if in_support:
            tr = voff + row * ncls
            for c in range(ncls):
                c0 = max(bounds[c], i0)
                c1 = min(bounds[c + 1], i1)
                e = trace[tr + c]
                if on_x != 0.0:
                    for i in range(c0, c1):
                        u = at(i)
                        t = theta[base + u] + coef[u] * e
                        theta[base + u] = t - on_x * fix[u]
                else:
                    for i in range(c0, c1):
                        u = at(i)
                        theta[base + u] += coef[u] * e
        elif on_x != 0.0:  # a row of x_t whose trace was cut
            for i in range(i0, i1):
                u = at(i)
                theta[base + u] -= on_x * fix[u]
        if on_next != 0.0:
            for i in range(i0, i1):
                u = at(i)
                theta[base + u] -= on_next * correction[u]
                acc[u] += on_next * theta[base + u]


@njit(**NO_NRT)
def store_values(b, i0, i1, lay, dem, scr):
    """Block b's demons i0 <= i < i1 read their new values at s_{t+1} (scr.values[0]) as value and prediction."""
    lo = lay.block_lo[b]
    for i in range(i0, i1):
        dem.q[lo + i, 0] = scr.values[0, i]
        dem.pred[lo + i] = scr.values[0, i]


@njit(**NO_NRT)
def finish(b, lay, cls, onl):
    """After every column learned: each class's continuation moves to s_{t+1}, and its rho_t becomes rho_{t-1}."""
    coff = lay.coff[b]
    for c in range(lay.ncls[b]):
        cls.gamma[coff + c] = cls.gamma_tp1[coff + c]
    keep_rho(b, lay, cls, onl)


@njit(**NO_NRT)
def keep_rho(b, lay, cls, onl):
    """Each class's rho_t becomes its rho_{t-1} (emphatic TD's followon, true online GTD's w trace)."""
    coff = lay.coff[b]
    for c in range(lay.ncls[b]):
        onl.cls_rho_prev[coff + c] = cls.rho[coff + c]
