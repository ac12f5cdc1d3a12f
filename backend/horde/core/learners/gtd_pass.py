"""GTD(lambda) (TDC) and the learners sharing its kernel (TDRC, GTD2, the original GTD): one pass over the weight
rows a step, each update deferred by one step (as `td_pass` defers TD's).

A step of GTD (`gradient.update`, `reference.gtd_step`) needs three sums before it may write any weight: theta .
x_{t+1} (the TD error), w . x_t and w . e_t; done in its own step, it reads x_{t+1}'s rows of theta, x_t's of w,
then reads and writes the support's rows of both (three passes). Here each step's update is owed instead, as
five numbers a demon (`Weights.owed`, rows OWED_*):

    theta owes  A e_t + M x_t - C x_{t+1}      A = alpha delta_t (TDC, TDRC; 0 for GTD2 and the original GTD)
                                               M = theta's move along x_t (GTD2: alpha (w . x_t); GTD: alpha rho_t
                                                   (u . x_t); 0 for TDC, TDRC)
                                               C = alpha gamma_{t+1} (1 - lambda) (w . e_t), the correction
    w owes      B e_t - D x_t                  B = alpha_w delta_t, D = alpha_w (w . x_t) (0 for the original GTD)

(times the scales of a w kept scaled: `tdrc.move_scales`). The next step's one walk over the union of the last
support, x_{t+1} and x_{t+2} (`columns`; as the step sees them, the support of e_{t-1}, x_t and x_{t+1}) pays all
of it row by row and reads from the rows just paid: theta . x_{t+1}, w . x_t and w . e_t, where e_t's value on a
row is computed in the walk from e_{t-1}'s exactly as the merge will store it (decay, add, cut, the trace's
dtype), so the cut costs nothing. Each support row of theta and w is read and written once, x_{t+1}'s other
rows of theta read once. x_t's value on each support row is kept beside it (`Weights.support_f`) for the
terms along x_t; x_t's rows that the merge leaves without a trace pay them at once, after the walk (they are in
no support: at cut 0 only where rho_t = 0). The traces then move to e_t (`finish`: the merge, after the walk
that still needed e_{t-1}), and the values at s_{t+1} come from the update's algebra,

    theta_{t+1} . x_{t+1} = theta_t . x_{t+1} + A (e_t . x_{t+1}) + M (x_t . x_{t+1}) - C (x_{t+1} . x_{t+1}).

What is owed is paid (`settle`, through `learners.settle`) wherever something outside the walk reads theta or w:
the end of a call of the loop, an episode's start, a freeze (`engine.step`). A frozen demon owes nothing.

A block of at least PARALLEL_MIN demons walks its rows in two halves instead, each taking every column (on two
threads, a thread each; `walk_half`, `join_halves`), as TD's does (`td_pass`). Within a row, each trace class's demons
are one contiguous run of the row (`Layout.class_lo`, `class_hi`). In float32 the walk pays in float32 (what is owed
and the row's numbers copied into the weights' dtype, `Scratch.ev`), and sums SUM_ROWS rows at a time in float32
before it adds them into float64 sums.

Why one module of about 500 lines: the walk (whole or in halves), the merge's follow-up in `finish` and `settle` pay
the same five numbers a demon, in the same order (a weight settled between calls must equal the one the walk would
have paid, to the bit), and read the same `Scratch` rows; apart, each would have to be kept in step with the others
by hand.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from horde.core.engine.layout import EV_ROWS, NO_NRT, OWED_ROWS
from horde.core.engine.rows import add_row, at, dot, fold_floor, square
from horde.core.engine.rows import td_error as td_error_at
from horde.core.engine.traces import above_cut, merge
from horde.core.engine.values import observe_range
from horde.core.learners.td_pass import half_start
from horde.core.learners.tdrc import SCALE_FLOOR, move_scales

FOLLOWS_DELTA, FOLLOWS_W, FOLLOWS_U = 0, 1, 2  # what theta follows besides the correction (see the module)
OWED_C, OWED_A, OWED_B, OWED_D, OWED_M = 0, 1, 2, 3, 4  # rows of `Weights.owed` (C: as GQ's correction, row 0)
NONE = np.int64(2**62)  # past every row: a walk's list that has ended
# Scratch.ev's rows, in the weights' dtype: what is owed as the walk pays it (K: A or M, whichever the form
# has; B, C, D), then cells of one number for a thread (at its first column) that round a row's numbers to the
# weights' dtype (of each of four rows: e_t's value, x_t's, x_{t-1}'s, x_{t+1}'s; `CELL_*`): sixteen rows for each
# half of a block that walks in halves (`walk_half`), so that the two halves' threads never write one cache line.
EV_K, EV_B, EV_C, EV_D, EV_CELLS, CELLS = 0, 1, 2, 3, 4, 16
CELL_N, CELL_F, CELL_P, CELL_G = 0, 1, 2, 3  # a row's cells: cells + 4 k + CELL_* for the k-th of four rows
assert OWED_ROWS == 5 and EV_ROWS == EV_CELLS + 2 * CELLS
# In float32 the walk's three sums (theta . x_{t+1}, w . x_t, w . e_t) are taken over SUM_ROWS rows at a time in
# float32 (`Scratch.sums`), then added into the float64 sums (`_add_sums`): a sum of so few terms does not drift,
# and per demon the float64 sums move twice a float32 weight's bytes (most of a float32 walk's, summed row by row).
# In float64, `Scratch.sums` is the float64 sums themselves. Half h of a walk in halves sums into rows 3 h to 3 h + 2
# of `Scratch.sums` and into `Scratch.work[1 + 3 h]` to `work[3 + 3 h]` (the first half's are the block's sums).
SUM_ROWS = 32


@njit(**NO_NRT, inline="always")
def prepare(b, lay, dem, cls, onl, scr, scaled):
    """What this step's trace moves by (decay gamma_t lambda rho_t, x_t adds rho_t: the merge is in `finish`), and
    how w is kept (`scaled`: tdrc's and the original GTD's scale moves on, `tdrc.move_scales`; else as it is)."""
    ncls, coff = lay.ncls[b], lay.coff[b]
    for c in range(ncls):
        rho = cls.rho[coff + c]
        scr.decay[c] = cls.gamma[coff + c] * lay.lam[b] * rho
        scr.add[c] = rho
    if scaled:
        move_scales(b, lay, dem, onl, scr, fold_floor(scr.ev, SCALE_FLOOR))
    else:
        scale_b, scale_d, scale_a = scr.scales[0], scr.scales[1], scr.scales[2]
        for i in range(lay.block_hi[b] - lay.block_lo[b]):
            scale_b[at(i)] = 1.0
            scale_d[at(i)] = 1.0
            scale_a[at(i)] = 1.0


@njit(**NO_NRT, inline="always")
def _cell(ev, r, i0, value):
    """value in the weights' dtype (row r of ev at the thread's first column: its own cell)."""
    ev[r, i0] = value
    return ev[r, i0]


@njit(**NO_NRT, inline="always")
def _new_trace(e_old, decay, add, f, cut, ev, r, i0):
    """e_t's value on a row as the merge will store it (`traces.merge`: decay, add, cut, the trace's dtype)."""
    t = e_old * decay + add * f
    return _cell(ev, r, i0, above_cut(t, cut))


@njit(**NO_NRT, inline="always")
def _pay_one(theta, w, base, c0, c1, own, sums, ev, acc):
    """One row's columns c0 <= i < c1: theta pays K k - C f, w pays B o - D p (own = (k, o, f, p) in the weights'
    dtype; k: e_{t-1}'s value on the row or x_{t-1}'s, as the form has it; o: e_{t-1}'s; f: x_t's; p:
    x_{t-1}'s); then the sums from the paid row (sums = (g, x, n); all in the weights' dtype, as are the partial
    sums acc): theta . x_{t+1} (g: x_{t+1}'s value), w . x_t (x: x_t's), w . e_t (n: e_t's)."""
    pay_k, pay_b, pay_c, pay_d = ev[EV_K], ev[EV_B], ev[EV_C], ev[EV_D]
    acc_v, acc_wx, acc_we = acc[0], acc[1], acc[2]
    k, o, f, p = own
    g, x, n = sums
    for i in range(c0, c1):  # theta's row, then w's (see `_pay_two`)
        u = at(i)
        th = theta[base + u] + pay_k[u] * k - pay_c[u] * f
        theta[base + u] = th
        acc_v[u] += g * th
    for i in range(c0, c1):
        u = at(i)
        wv = w[base + u] + pay_b[u] * o - pay_d[u] * p
        w[base + u] = wv
        acc_wx[u] += x * wv
        acc_we[u] += n * wv


@njit(**NO_NRT, inline="always")
def _pay_two(theta, w, bases, c0, c1, own, sums, ev, acc):
    """`_pay_one` on two rows at once (more memory streams in flight): each of own = (k, o, f, p) and sums =
    (g, x, n) holds both rows' numbers, the first row's first.

    theta's rows and w's are two loops: LLVM checks at run time that a loop's arrays do not overlap before it
    takes the vector path, and the checks grow with the pairs of arrays. With short loops (the thesis loop's GTD
    block: 98 demons in 4 classes, about 25 columns a loop) they cost as much as the loop: in one loop of nine
    arrays, five written, a quarter of the walk's time went to them. Two loops of five and six arrays check
    less than half as much and read nothing twice: that block's step took 4.58 us instead of 4.93."""
    pay_k, pay_b, pay_c, pay_d = ev[EV_K], ev[EV_B], ev[EV_C], ev[EV_D]
    acc_v, acc_wx, acc_we = acc[0], acc[1], acc[2]
    k0, k1, o0, o1, f0, f1, p0, p1 = own
    g0, g1, x0, x1, n0, n1 = sums
    base0, base1 = bases
    for i in range(c0, c1):  # theta's rows, then w's (see the docstring)
        u = at(i)
        th0 = theta[base0 + u] + pay_k[u] * k0 - pay_c[u] * f0
        th1 = theta[base1 + u] + pay_k[u] * k1 - pay_c[u] * f1
        theta[base0 + u] = th0
        theta[base1 + u] = th1
        acc_v[u] += g0 * th0 + g1 * th1
    for i in range(c0, c1):
        u = at(i)
        wv0 = w[base0 + u] + pay_b[u] * o0 - pay_d[u] * p0
        wv1 = w[base1 + u] + pay_b[u] * o1 - pay_d[u] * p1
        w[base0 + u] = wv0
        w[base1 + u] = wv1
        acc_wx[u] += x0 * wv0 + x1 * wv1
        acc_we[u] += n0 * wv0 + n1 * wv1


@njit(**NO_NRT, inline="always")
def _pay_four(theta, w, bases, c0, c1, own, sums, ev, acc):
    """`_pay_two` on four rows at once, the first pair's sums added before the second's as two calls would (the
    same numbers to the last bit), with the sums read and written once for the four rows and four rows' streams
    in flight (as TD's `td_pass._pay_and_read_four`). own = (k, o, f, p) and sums = (g, x, n), each of four rows."""
    pay_k, pay_b, pay_c, pay_d = ev[EV_K], ev[EV_B], ev[EV_C], ev[EV_D]
    acc_v, acc_wx, acc_we = acc[0], acc[1], acc[2]
    (k0, k1, k2, k3), (o0, o1, o2, o3), (f0, f1, f2, f3), (p0, p1, p2, p3) = own
    (g0, g1, g2, g3), (x0, x1, x2, x3), (n0, n1, n2, n3) = sums
    base0, base1, base2, base3 = bases
    for i in range(c0, c1):  # theta's rows, then w's (see `_pay_two`)
        u = at(i)
        th0 = theta[base0 + u] + pay_k[u] * k0 - pay_c[u] * f0
        th1 = theta[base1 + u] + pay_k[u] * k1 - pay_c[u] * f1
        th2 = theta[base2 + u] + pay_k[u] * k2 - pay_c[u] * f2
        th3 = theta[base3 + u] + pay_k[u] * k3 - pay_c[u] * f3
        theta[base0 + u] = th0
        theta[base1 + u] = th1
        theta[base2 + u] = th2
        theta[base3 + u] = th3
        acc_v[u] = (acc_v[u] + (g0 * th0 + g1 * th1)) + (g2 * th2 + g3 * th3)
    for i in range(c0, c1):
        u = at(i)
        wv0 = w[base0 + u] + pay_b[u] * o0 - pay_d[u] * p0
        wv1 = w[base1 + u] + pay_b[u] * o1 - pay_d[u] * p1
        wv2 = w[base2 + u] + pay_b[u] * o2 - pay_d[u] * p2
        wv3 = w[base3 + u] + pay_b[u] * o3 - pay_d[u] * p3
        w[base0 + u] = wv0
        w[base1 + u] = wv1
        w[base2 + u] = wv2
        w[base3 + u] = wv3
        acc_wx[u] = (acc_wx[u] + (x0 * wv0 + x1 * wv1)) + (x2 * wv2 + x3 * wv3)
        acc_we[u] = (acc_we[u] + (n0 * wv0 + n1 * wv1)) + (n2 * wv2 + n3 * wv3)


@njit(**NO_NRT, inline="always")
def _row_cells(ev, cells, i0, f, p, g):
    """A row's x_t, x_{t-1} and x_{t+1} values in the weights' dtype (its cells from `cells` on)."""
    return _cell(ev, cells + CELL_F, i0, f), _cell(ev, cells + CELL_P, i0, p), _cell(ev, cells + CELL_G, i0, g)


@njit(**NO_NRT)
def _pay_rows(b, i0, i1, lay, wts, scr, n, r, values, h, form):
    """The walk's rows r[0] to r[n - 1] (n: 1, 2 or 4), each class's run of columns i0 <= i < i1 (see `_pay_one`),
    summed into half h's sums; values = (x, q, g): x_t's values on the four rows, x_{t-1}'s, x_{t+1}'s (float64;
    rounded to the weights' dtype here, in half h's cells)."""
    lo, woff, voff, ncls, coff, cut = lay.block_lo[b], lay.woff[b], lay.voff[b], lay.ncls[b], lay.coff[b], lay.cut
    db = lay.block_hi[b] - lo
    theta, w, trace, ev, acc = wts.theta, wts.w, wts.trace, scr.ev, scr.sums[3 * h : 3 * h + 3]
    cells = EV_CELLS + CELLS * h
    r0, r1, r2, r3 = r
    x, q, g = values
    bases = (at(woff + r0 * db), at(woff + r1 * db), at(woff + r2 * db), at(woff + r3 * db))
    f0, p0, g0 = _row_cells(ev, cells, i0, x[0], q[0], g[0])
    f1, p1, g1 = _row_cells(ev, cells + 4, i0, x[1], q[1], g[1])
    f2, p2, g2 = _row_cells(ev, cells + 8, i0, x[2], q[2], g[2])
    f3, p3, g3 = _row_cells(ev, cells + 12, i0, x[3], q[3], g[3])
    for c in range(ncls):
        c0 = max(lay.class_lo[coff + c], i0)
        c1 = min(lay.class_hi[coff + c], i1)
        if c0 >= c1:
            continue
        decay, add = scr.decay[c], scr.add[c]
        o0 = trace[voff + r0 * ncls + c]  # (a row off the last support has trace 0)
        n0 = _new_trace(o0, decay, add, x[0], cut, ev, cells + CELL_N, i0)
        k0 = o0 if form == FOLLOWS_DELTA else p0
        if n == 1:
            _pay_one(theta, w, bases[0], c0, c1, (k0, o0, f0, p0), (g0, f0, n0), ev, acc)
            continue
        o1 = trace[voff + r1 * ncls + c]
        n1 = _new_trace(o1, decay, add, x[1], cut, ev, cells + 4 + CELL_N, i0)
        k1 = o1 if form == FOLLOWS_DELTA else p1
        if n == 2:
            own2 = (k0, k1, o0, o1, f0, f1, p0, p1)
            _pay_two(theta, w, (bases[0], bases[1]), c0, c1, own2, (g0, g1, f0, f1, n0, n1), ev, acc)
            continue
        o2, o3 = trace[voff + r2 * ncls + c], trace[voff + r3 * ncls + c]
        n2 = _new_trace(o2, decay, add, x[2], cut, ev, cells + 8 + CELL_N, i0)
        n3 = _new_trace(o3, decay, add, x[3], cut, ev, cells + 12 + CELL_N, i0)
        k2, k3 = (o2, o3) if form == FOLLOWS_DELTA else (p2, p3)
        own = ((k0, k1, k2, k3), (o0, o1, o2, o3), (f0, f1, f2, f3), (p0, p1, p2, p3))
        _pay_four(theta, w, bases, c0, c1, own, ((g0, g1, g2, g3), (f0, f1, f2, f3), (n0, n1, n2, n3)), ev, acc)


@njit(**NO_NRT, inline="always")
def _add_sums(i0, i1, scr, h):
    """float32: half h's sums over its last rows (`Scratch.sums`) added into its float64 sums, and begun again."""
    for r in range(3):
        part, total = scr.sums[3 * h + r], scr.work[1 + 3 * h + r]
        for i in range(i0, i1):
            u = at(i)
            total[u] += np.float64(part[u])
            part[u] = 0.0


@njit(**NO_NRT, inline="always")
def _begin(b, i0, i1, lay, wts, scr, halves):
    """Block b's demons i0 <= i < i1: what they owe, in the weights' dtype, as the walk pays it; the float64 sums of
    the walk (of both halves, `halves` = 2) at 0. (float32's partial sums start at 0: allocated so, and every walk's
    last `_add_sums` leaves its columns at 0.)"""
    lo, owed, ev, work = lay.block_lo[b], wts.owed, scr.ev, scr.work
    owed_a, owed_b, owed_c, owed_d, owed_m = owed[OWED_A], owed[OWED_B], owed[OWED_C], owed[OWED_D], owed[OWED_M]
    pay_k, pay_b, pay_c, pay_d = ev[EV_K], ev[EV_B], ev[EV_C], ev[EV_D]
    for i in range(i0, i1):  # (rows and unsigned offsets: the per-demon loops vectorize, `rows.at`)
        u, d = at(i), at(lo + i)
        pay_k[u] = owed_a[d] + owed_m[d]  # (one of the two is 0: `form`)
        pay_b[u] = owed_b[d]
        pay_c[u] = owed_c[d]
        pay_d[u] = owed_d[d]
    for r in range(1, 1 + 3 * halves):
        for i in range(i0, i1):
            work[r, at(i)] = 0.0


@njit(**NO_NRT)
def _walk(b, i0, i1, rows, h, lay, wts, stp, scr, form):
    """Block b's demons i0 <= i < i1 walk the last support's rows s0 <= s < s1, x_t's j0 <= j < j1 and x_{t+1}'s
    m0 <= m < m1 (rows: (s0, s1, j0, j1, m0, m1)): each row paid and read (the rows that pay, four at a time), the
    sums into half h's (see the module)."""
    woff, toff = lay.woff[b], lay.toff[b]
    db = lay.block_hi[b] - lay.block_lo[b]
    theta, support, support_f, ev = wts.theta, wts.support, wts.support_f, scr.ev
    part_v, in_float32 = scr.sums[3 * h], theta.itemsize == 4  # (float32: theta . x_{t+1} over the last rows)
    sum_rows = SUM_ROWS if in_float32 else NONE
    x_t, v_t, x_tp1, v_tp1 = stp.x_t, stp.v_t, stp.x_tp1, stp.v_tp1
    s, old, j, nt, m, k = rows
    summed = 0  # rows in the partial sums
    # The rows that pay are held until there are four (then paid at once); waiting: how many are held, with each
    # one's row, x_t's value, x_{t-1}'s and x_{t+1}'s.
    waiting = 0
    r0 = r1 = r2 = np.int64(0)
    x0 = x1 = x2 = q0 = q1 = q2 = g0 = g1 = g2 = 0.0
    while s < old or j < nt or m < k:
        r_s = support[toff + s] if s < old else NONE
        r_j = x_t[j] if j < nt else NONE
        r_m = x_tp1[m] if m < k else NONE
        row = min(r_s, min(r_j, r_m))
        g = v_tp1[m] if r_m == row else 0.0
        if r_s == row or r_j == row:
            x = v_t[j] if r_j == row else 0.0
            q = support_f[toff + s] if r_s == row else 0.0
            if waiting == 3:
                values4 = ((x0, x1, x2, x), (q0, q1, q2, q), (g0, g1, g2, g))
                _pay_rows(b, i0, i1, lay, wts, scr, 4, (r0, r1, r2, row), values4, h, form)
                summed += 4
                waiting = 0
            else:
                if waiting == 0:
                    r0, x0, q0, g0 = row, x, q, g
                elif waiting == 1:
                    r1, x1, q1, g1 = row, x, q, g
                else:
                    r2, x2, q2, g2 = row, x, q, g
                waiting += 1
            s += 1 if r_s == row else 0
            j += 1 if r_j == row else 0
        elif g != 0.0:  # a row of x_{t+1} alone: theta read only (it owes nothing there)
            add_row(i0, i1, at(woff + row * db), theta, part_v, _cell(ev, EV_CELLS + CELLS * h + CELL_G, i0, g))
            summed += 1
        m += 1 if r_m == row else 0
        if summed >= sum_rows:
            _add_sums(i0, i1, scr, h)
            summed = 0
    if waiting >= 2:  # the last rows held: a pair, then one
        values2 = ((x0, x1, x1, x1), (q0, q1, q1, q1), (g0, g1, g1, g1))
        _pay_rows(b, i0, i1, lay, wts, scr, 2, (r0, r1, r1, r1), values2, h, form)
    if waiting % 2 == 1:  # (one held, or the third)
        r_l, x_l, q_l, g_l = (r0, x0, q0, g0) if waiting == 1 else (r2, x2, q2, g2)
        values1 = ((x_l, x_l, x_l, x_l), (q_l, q_l, q_l, q_l), (g_l, g_l, g_l, g_l))
        _pay_rows(b, i0, i1, lay, wts, scr, 1, (r_l, r_l, r_l, r_l), values1, h, form)
    if in_float32:
        _add_sums(i0, i1, scr, h)


@njit(**NO_NRT)
def _owe(b, i0, i1, lay, wts, dem, cls, stp, scr, form):
    """Block b's demons i0 <= i < i1, the walk's sums in scr.work[1:4]: the TD errors and what this step owes; x_t's
    rows left without a trace pay its terms along x_t at once."""
    lo, woff, voff, ncls, coff = lay.block_lo[b], lay.woff[b], lay.voff[b], lay.ncls[b], lay.coff[b]
    db = lay.block_hi[b] - lo
    theta, w, trace, owed, ev, cut, lam = wts.theta, wts.w, wts.trace, wts.owed, scr.ev, lay.cut, lay.lam[b]
    owed_a, owed_b, owed_c, owed_d, owed_m = owed[OWED_A], owed[OWED_B], owed[OWED_C], owed[OWED_D], owed[OWED_M]
    acc_v, acc_wx, acc_we = scr.work[1], scr.work[2], scr.work[3]  # theta . x_{t+1}, w . x_t, w . e_t
    q_t, values, scale_b, scale_d, scale_a = dem.q[:, 0], scr.values[0], scr.scales[0], scr.scales[1], scr.scales[2]
    for i in range(i0, i1):
        u, d = at(i), at(lo + i)
        g1 = cls.gamma_tp1[lay.slot_class[d]]
        dl = td_error_at(dem.r[d], dem.z[d], g1, acc_v[u], q_t[d])
        dem.delta[d] = dl
        values[u] = acc_v[u]
        a, a_w = dem.alpha[d], dem.alpha_w[d]  # a frozen demon (step sizes 0) owes nothing, whatever its delta
        owed_a[d] = a * dl if a != 0.0 and form == FOLLOWS_DELTA else 0.0
        owed_b[d] = a_w * dl * scale_b[u] if a_w != 0.0 else 0.0
        owed_d[d] = a_w * acc_wx[u] * scale_d[u] if a_w != 0.0 and form != FOLLOWS_U else 0.0
        move = a * acc_wx[u] * scale_a[u] if a != 0.0 and form != FOLLOWS_DELTA else 0.0
        owed_m[d] = move * scr.add[lay.slot_class[d] - coff] if form == FOLLOWS_U else move  # (rho_t)
        owed_c[d] = a * g1 * (1.0 - lam) * acc_we[u] * scale_a[u] if a != 0.0 else 0.0
    # x_t's rows that the merge will leave without a trace (in no support next step): its terms along x_t now
    x_t, v_t = stp.x_t, stp.v_t
    for j in range(x_t.shape[0]):
        row = x_t[j]
        f = v_t[j]
        left = False
        for c in range(ncls):
            e_new = _new_trace(trace[voff + row * ncls + c], scr.decay[c], scr.add[c], f, cut, ev, EV_CELLS, i0)
            left = left or e_new != 0.0
        if left:
            continue
        base = at(woff + row * db)
        for i in range(i0, i1):
            u = at(i)
            w[base + u] -= f * owed_d[at(lo + i)]
            theta[base + u] += f * owed_m[at(lo + i)]


@njit(**NO_NRT)
def columns(b, i0, i1, lay, wts, dem, cls, stp, scr, form):
    """Block b's demons i0 <= i < i1 (see the module): one walk over the last support, x_t and x_{t+1} pays what
    the last step owes and sums theta . x_{t+1}, w . x_t and w . e_t from the paid rows; then the TD errors and what
    this step owes."""
    if i0 >= i1:
        return
    _begin(b, i0, i1, lay, wts, scr, 1)
    rows = (np.int64(0), np.int64(wts.nnz[b]), np.int64(0), np.int64(stp.x_t.shape[0]), np.int64(0),
            np.int64(stp.x_tp1.shape[0]))  # fmt: skip
    _walk(b, i0, i1, rows, i0 - i0, lay, wts, stp, scr, form)  # (half 0, typed int64 as `walk_half`'s h)
    _owe(b, i0, i1, lay, wts, dem, cls, stp, scr, form)


# A wide block (`td_pass.walks_in_halves`) walks its rows in two halves, as TD's does: the last support's first half
# of rows with x_t's and x_{t+1}'s rows below the second half's first row, and the rest; on two threads each half
# takes every column (each thread streams whole rows), each summing its own sums, added in that order after both.


@njit(**NO_NRT)
def before_halves(b, lay, wts, scr):
    """A block that walks in halves: what it owes in the weights' dtype, both halves' sums at 0 (`_begin`)."""
    db = lay.block_hi[b] - lay.block_lo[b]
    _begin(b, db - db, db, lay, wts, scr, 2)


@njit(**NO_NRT)
def walk_half(h, b, i0, i1, lay, wts, stp, scr, form):
    """Block b's demons i0 <= i < i1 walk half h of the rows (see above)."""
    kept, nt, k = np.int64(wts.nnz[b]), np.int64(stp.x_t.shape[0]), np.int64(stp.x_tp1.shape[0])
    middle, first = half_start(b, lay, wts)
    j_middle, m_middle = np.int64(np.searchsorted(stp.x_t, first)), np.int64(np.searchsorted(stp.x_tp1, first))
    if h == 0:
        rows = (kept - kept, middle, nt - nt, j_middle, k - k, m_middle)
    else:
        rows = (middle, kept, j_middle, nt, m_middle, k)
    _walk(b, i0, i1, rows, h, lay, wts, stp, scr, form)


@njit(**NO_NRT)
def join_halves(b, lay, wts, dem, cls, stp, scr, form):
    """After both halves: each demon's sums are the first half's plus the second's; then the TD errors and what
    this step owes (`_owe`)."""
    db = lay.block_hi[b] - lay.block_lo[b]
    for r in range(1, 4):
        for i in range(db):
            scr.work[r, at(i)] += scr.work[r + 3, at(i)]
    _owe(b, db - db, db, lay, wts, dem, cls, stp, scr, form)


@njit(**NO_NRT, inline="always")
def finish(b, lay, wts, dem, cls, onl, stp, scr, scaled):
    """After every column: the traces move to e_t (the merge; x_t's value on each support row kept beside it), the
    values at s_{t+1} take what this step owes (the module's algebra) and become the demons' values and
    predictions; each class's continuation moves to s_{t+1}; a w kept scaled folds a scale below SCALE_FLOOR."""
    lo, voff, ncls, coff, toff = lay.block_lo[b], lay.voff[b], lay.ncls[b], lay.coff[b], lay.toff[b]
    db = lay.block_hi[b] - lo
    kept, _ = merge(b, lay, wts, scr, stp.x_t, stp.v_t, 0, False)
    for s in range(kept):
        wts.support_f[toff + s] = scr.rows_f[s]
    trace, values, value = wts.trace, scr.values, scr.values[0]
    owed_a, owed_m, owed_c = wts.owed[OWED_A], wts.owed[OWED_M], wts.owed[OWED_C]
    x_tp1, v_tp1 = stp.x_tp1, stp.v_tp1
    shared = dot(stp.x_t, stp.v_t, x_tp1, v_tp1)
    own_dot = square(v_tp1)
    for c in range(ncls):
        e_dot_x = 0.0
        for j in range(x_tp1.shape[0]):
            e_dot_x += v_tp1[j] * np.float64(trace[voff + x_tp1[j] * ncls + c])
        for i in range(lay.class_lo[coff + c], lay.class_hi[coff + c]):
            u, d = at(i), at(lo + i)
            value[u] += owed_a[d] * e_dot_x + owed_m[d] * shared - owed_c[d] * own_dot
    observe_range(b, 0, db, lay, dem, cls, values)
    for c in range(ncls):
        cls.gamma[coff + c] = cls.gamma_tp1[coff + c]
    if scaled:
        _fold(b, lay, wts, onl)


@njit(**NO_NRT)
def _fold(b, lay, wts, onl):
    """A demon's scale of w below SCALE_FLOOR (float32: `rows.fold_floor`) folded back into w (and into what w
    owes, in the same units)."""
    lo, woff, rows = lay.block_lo[b], lay.woff[b], lay.rows[b]
    db = lay.block_hi[b] - lo
    floor = fold_floor(wts.w, SCALE_FLOOR)
    for i in range(db):
        s = onl.scale[lo + i]
        if s < floor:
            for row in range(rows):
                wts.w[woff + row * db + i] *= s
            wts.owed[OWED_B, lo + i] *= s
            wts.owed[OWED_D, lo + i] *= s
            onl.scale[lo + i] = 1.0


@njit(**NO_NRT)
def settle(b, lay, wts, x, v):
    """Pay what block b owes (the module's five numbers a demon: on the support's rows, with x_t's value kept
    beside each, and on the rows x of x_{t+1}, values v); owe nothing more."""
    lo, woff, voff, ncls, coff, toff = lay.block_lo[b], lay.woff[b], lay.voff[b], lay.ncls[b], lay.coff[b], lay.toff[b]
    db = lay.block_hi[b] - lo
    owed = wts.owed
    owing = False
    for r in range(OWED_ROWS):
        for i in range(db):
            owing = owing or owed[r, lo + i] != 0.0
    if not owing:
        return
    theta, w, trace, support = wts.theta, wts.w, wts.trace, wts.support
    pay_a, pay_b, pay_c = owed[OWED_A, lo : lo + db], owed[OWED_B, lo : lo + db], owed[OWED_C, lo : lo + db]
    pay_d, pay_m = owed[OWED_D, lo : lo + db], owed[OWED_M, lo : lo + db]
    for s in range(wts.nnz[b]):
        row = support[toff + s]
        f = wts.support_f[toff + s]
        base = at(woff + row * db)
        for c in range(ncls):
            e = np.float64(trace[voff + row * ncls + c])
            for i in range(lay.class_lo[coff + c], lay.class_hi[coff + c]):
                u = at(i)
                theta[base + u] += pay_a[u] * e + pay_m[u] * f  # (one of the two is 0: the walk's sum, bit for bit)
                w[base + u] = w[base + u] + pay_b[u] * e - pay_d[u] * f  # (the walk's order)
    for j in range(x.shape[0]):
        base = at(woff + x[j] * db)
        for i in range(db):
            theta[base + at(i)] -= v[j] * pay_c[at(i)]
    for r in range(OWED_ROWS):
        for i in range(db):
            owed[r, lo + i] = 0.0
