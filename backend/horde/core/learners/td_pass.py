"""TD(lambda)'s compiled kernel: one pass over the weight rows a step, each update deferred by one step.

TD's update theta += alpha delta_t e_t needs delta_t, which needs theta . x_{t+1}: a step that applies its own
update reads x_{t+1}'s rows for the TD error, then reads and writes the support's, then reads x_{t+1}'s again
for the new values (three passes; docs/performance.md, "Why 0.7 is not reached"). Here the update is owed
instead: `Weights.owed[0, d]` holds alpha delta_t of demon d, and the trace e_t is left as it is, so theta
owes owed[d] e_t. The next step's one pass over the union of the support's rows and x_{t+2}'s (`columns`)
pays it row by row and reads the values at x_{t+2} from the rows just paid: each row read and written once,
x_{t+2}'s other rows read once. The trace then moves to e_{t+1} (`finish`: the merge, after the pass that
still needed e_t), and the new values at s_{t+2} come from the update's algebra,

    theta_{t+2} . x_{t+2} = theta_{t+1} . x_{t+2} + alpha delta_{t+1} (e_{t+1} . x_{t+2}),

with e . x one sum per trace class. What is owed is paid (`settle`) wherever something outside the pass reads
theta: the end of a call of the loop, an episode's start (traces cleared, demons that forget their weights),
a freeze (the block's values read again): `horde.core.engine.step.settle`, `step.observe`,
`step.freeze_diverged`. So nothing outside the loop sees a weight that owes.

Within a row, each trace class's demons are one contiguous run of the row (`Layout.class_lo`, `class_hi`):
the class's trace value is one number for the run. float32 weights and traces are read into float64 sums.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from horde.core.engine.layout import NO_NRT, PARALLEL_MIN
from horde.core.engine.rows import at, dot
from horde.core.engine.rows import td_error as td_error_at
from horde.core.engine.traces import merge
from horde.core.engine.values import observe_range

NONE = np.int64(2**62)  # past every row: a walk's list that has ended


@njit(**NO_NRT, inline="always")
def prepare(b, lay, cls, scr):
    """What this step's merge (in `finish`) decays each class's trace by (gamma_t lambda rho_t) and what x_t adds
    (rho_t); the traces themselves still hold e_{t-1}, which the pass pays with."""
    ncls, coff = lay.ncls[b], lay.coff[b]
    for c in range(ncls):
        rho = cls.rho[coff + c]
        scr.decay[c] = cls.gamma[coff + c] * lay.lam[b] * rho
        scr.add[c] = rho


@njit(**NO_NRT, inline="always")
def _pay(theta, base, owed, e, c0, c1):
    """theta pays owed[i] e on the row at base, columns c0 <= i < c1."""
    for i in range(c0, c1):
        u = at(i)
        theta[base + u] += owed[u] * e


@njit(**NO_NRT, inline="always")
def _pay_and_read(theta, base, owed, e, c0, c1, acc, value):
    """`_pay`, and acc[i] += value times the paid weight (as stored: float32 rounds before it is read)."""
    for i in range(c0, c1):
        u = at(i)
        theta[base + u] += owed[u] * e
        acc[u] += value * theta[base + u]


@njit(**NO_NRT, inline="always")
def _pay_and_read_two(theta, bases, owed, e, c0, c1, acc, value):
    """`_pay_and_read` on two rows at once (bases, e and value hold both rows' numbers, the first row's first): acc,
    float64, is read and written once for the two rows. Row by row, acc moved as many bytes per demon as theta in
    float64 and twice as many in float32; paired, a nexting step took 0.8 to 0.9 of its time (docs/performance.md,
    "Two rows at once")."""
    base0, base1 = bases
    e0, e1 = e
    value0, value1 = value
    for i in range(c0, c1):
        u = at(i)
        paid0 = theta[base0 + u] + owed[u] * e0
        paid1 = theta[base1 + u] + owed[u] * e1
        theta[base0 + u] = paid0
        theta[base1 + u] = paid1
        acc[u] += value0 * paid0 + value1 * paid1


@njit(**NO_NRT, inline="always")
def _pay_and_read_four(theta, bases, owed, e, c0, c1, acc, value):
    """`_pay_and_read_two` on four rows at once, the first pair's sum added to acc before the second's as two calls
    would: the same numbers to the last bit, with acc read and written once for the four rows and four rows'
    streams in flight (docs/performance.md, "Four rows at once")."""
    base0, base1, base2, base3 = bases
    e0, e1, e2, e3 = e
    value0, value1, value2, value3 = value
    for i in range(c0, c1):
        u = at(i)
        paid0 = theta[base0 + u] + owed[u] * e0
        paid1 = theta[base1 + u] + owed[u] * e1
        paid2 = theta[base2 + u] + owed[u] * e2
        paid3 = theta[base3 + u] + owed[u] * e3
        theta[base0 + u] = paid0
        theta[base1 + u] = paid1
        theta[base2 + u] = paid2
        theta[base3 + u] = paid3
        acc[u] = (acc[u] + (value0 * paid0 + value1 * paid1)) + (value2 * paid2 + value3 * paid3)


@njit(**NO_NRT, inline="always")
def _paid_and_read(support, toff, s, s1, x_tp1, v_tp1, m, m1):
    """How many of the walk's rows from the support's s and x_{t+1}'s m on, up to four, are both paid and read (each
    the next row of both lists, with a value there), so that they go at once."""
    n = 0
    while n < 4 and s + n < s1 and m + n < m1 and x_tp1[m + n] == support[toff + s + n] and v_tp1[m + n] != 0.0:
        n += 1
    return n


@njit(**NO_NRT, inline="always")
def _pay_with_fix(theta, base, owed, e, fix, f, c0, c1):
    """theta pays owed[i] e - fix[i] f on the row at base (true online TD: f, x_{t-1}'s value there)."""
    for i in range(c0, c1):
        u = at(i)
        theta[base + u] += owed[u] * e - fix[u] * f


@njit(**NO_NRT, inline="always")
def _pay_along(theta, base, owed, e, fix, f, c0, c1, acc, value):
    """theta pays owed[i] e - fix[i] f on the row at base (true online TD: f, x_{t-1}'s value there), and acc[i] +=
    value times the paid weight."""
    for i in range(c0, c1):
        u = at(i)
        theta[base + u] += owed[u] * e - fix[u] * f
        acc[u] += value * theta[base + u]


@njit(**NO_NRT, inline="always")
def owed_to_pay(b, i0, i1, lay, wts, scr, along_x):
    """Block b's demons i0 <= i < i1: what they owe, in the weights' dtype (scr.ev[0], `along_x`: ev[1]), as the
    walk pays it (float32 pays in float32, twice the width)."""
    lo = lay.block_lo[b]
    for i in range(i0, i1):
        scr.ev[0, i] = wts.owed[0, lo + i]
        scr.ev[1, i] = wts.owed[1, lo + i] if along_x else 0.0


@njit(**NO_NRT)
def walk(b, i0, i1, lay, wts, stp, scr, along_x):
    """Block b's demons i0 <= i < i1: one walk over the support's rows and x_{t+1}'s (both sorted) pays what the
    last step owes on the support (owed[0] e_{t-1}; `along_x`: and - owed[1] times x_{t-1}'s value, kept beside
    each support row) and sums the values at x_{t+1} from the paid rows (into scr.values[0])."""
    owed_to_pay(b, i0, i1, lay, wts, scr, along_x)
    rows = (np.int64(0), np.int64(wts.nnz[b]), np.int64(0), np.int64(stp.x_tp1.shape[0]))
    walk_rows(b, i0, i1, rows, lay, wts, stp, scr, scr.values[0], along_x)


@njit(**NO_NRT)
def walk_rows(b, i0, i1, rows, lay, wts, stp, scr, acc, along_x):
    """`walk` over the support's rows s0 <= s < s1 and x_{t+1}'s rows m0 <= m < m1 (rows: (s0, s1, m0, m1); what
    it pays already in scr.ev), the values summed into acc. Four rows in a row that are all paid and read go at once,
    else two (TD's; true online TD pays along x_{t-1} too, one row at a time)."""
    s0, s1, m0, m1 = rows
    woff, voff, ncls, coff, toff = lay.woff[b], lay.voff[b], lay.ncls[b], lay.coff[b], lay.toff[b]
    db = lay.block_hi[b] - lay.block_lo[b]
    theta, trace, support = wts.theta, wts.trace, wts.support
    pay, fix = scr.ev[0], scr.ev[1]
    x_tp1, v_tp1 = stp.x_tp1, stp.v_tp1
    for i in range(i0, i1):
        acc[i] = 0.0
    s = s0
    m = m0
    while s < s1 or m < m1:
        r_s = support[toff + s] if s < s1 else NONE
        r_m = x_tp1[m] if m < m1 else NONE
        row = min(r_s, r_m)
        base = at(woff + row * db)
        value = v_tp1[m] if r_m == row else 0.0
        together = 0 if along_x or r_s != row else _paid_and_read(support, toff, s, s1, x_tp1, v_tp1, m, m1)
        if together == 4:  # the next four rows are paid and read: at once
            rows4 = (row, support[toff + s + 1], support[toff + s + 2], support[toff + s + 3])
            bases4 = (base, at(woff + rows4[1] * db), at(woff + rows4[2] * db), at(woff + rows4[3] * db))
            values4 = (value, v_tp1[m + 1], v_tp1[m + 2], v_tp1[m + 3])
            for c in range(ncls):
                c0 = max(lay.class_lo[coff + c], i0)
                c1 = min(lay.class_hi[coff + c], i1)
                e4 = (trace[voff + rows4[0] * ncls + c], trace[voff + rows4[1] * ncls + c],
                      trace[voff + rows4[2] * ncls + c], trace[voff + rows4[3] * ncls + c])  # fmt: skip
                _pay_and_read_four(theta, bases4, pay, e4, c0, c1, acc, values4)
            s += 4
            m += 4
            continue
        if together >= 2:  # the next two rows: at once
            row1 = support[toff + s + 1]
            bases = (base, at(woff + row1 * db))
            tr0, tr1 = voff + row * ncls, voff + row1 * ncls
            for c in range(ncls):
                c0 = max(lay.class_lo[coff + c], i0)
                c1 = min(lay.class_hi[coff + c], i1)
                e = (trace[tr0 + c], trace[tr1 + c])
                _pay_and_read_two(theta, bases, pay, e, c0, c1, acc, (value, v_tp1[m + 1]))
            s += 2
            m += 2
            continue
        if r_s == row:
            tr = voff + row * ncls
            f = wts.support_f[toff + s] if along_x else 0.0
            if f != 0.0:
                scr.ev[2, i0] = f  # x_{t-1}'s value in the weights' dtype (the thread's own cell)
                f = scr.ev[2, i0]
            for c in range(ncls):
                c0 = max(lay.class_lo[coff + c], i0)
                c1 = min(lay.class_hi[coff + c], i1)
                e = trace[tr + c]
                if f != 0.0:
                    _pay_along(theta, base, pay, e, fix, f, c0, c1, acc, value)
                elif value != 0.0:
                    _pay_and_read(theta, base, pay, e, c0, c1, acc, value)
                elif e != 0.0:
                    _pay(theta, base, pay, e, c0, c1)
            s += 1
        elif value != 0.0:  # a row of x_{t+1} outside the support: read only
            for i in range(i0, i1):
                u = at(i)
                acc[u] += value * theta[base + u]
        if r_m == row:
            m += 1


@njit(**NO_NRT)
def errors(b, i0, i1, lay, wts, dem, cls, scr):
    """Block b's demons i0 <= i < i1, their values at x_{t+1} in scr.values[0]: the TD errors, and alpha delta
    owed for the next walk (0 for a frozen demon)."""
    lo, coff = lay.block_lo[b], lay.coff[b]
    owed, acc = wts.owed[0], scr.values[0]
    for c in range(coff, coff + lay.ncls[b]):  # a class's run of demons at a time: its continuation is one number
        gamma_tp1 = cls.gamma_tp1[c]
        for i in range(max(lay.class_lo[c], i0), min(lay.class_hi[c], i1)):
            d = lo + i
            dl = td_error_at(dem.r[d], dem.z[d], gamma_tp1, acc[i], dem.q[d, 0])
            dem.delta[d] = dl
            owed[d] = dem.alpha[d] * dl if dem.alpha[d] != 0.0 else 0.0  # a frozen demon stays exactly as it is


@njit(**NO_NRT)
def columns(b, i0, i1, lay, wts, dem, cls, stp, scr):
    """Block b's demons i0 <= i < i1: the walk (pays what the last step owes, sums the values at x_{t+1}); then the
    TD errors, and alpha delta owed for the next walk."""
    walk(b, i0, i1, lay, wts, stp, scr, False)
    errors(b, i0, i1, lay, wts, dem, cls, scr)


# A wide block (`walks_in_halves`) walks its rows in two halves: the support's first half of rows with x_{t+1}'s
# rows below the second half's first row, and the rest. On two threads each half takes every column, each
# thread streaming whole rows: a split of the columns halves each row's contiguous run and each class's, and
# walked 1.55 times as fast as one thread where the halves walked 1.74 times (float32: 1.57 and 2.11;
# docs/performance.md, "TD's rows in two halves"). Each half sums its own values (the first into scr.values[0],
# the second into scr.work[0]), added in that order after both: the same operations whatever the thread count.


@njit(**NO_NRT, inline="always")
def walks_in_halves(db):
    """Whether a block of db demons walks its rows in two halves (a block that may split over threads): TD's, and
    GTD's (`gtd_pass.walk_half`)."""
    return db >= PARALLEL_MIN


@njit(**NO_NRT, inline="always")
def half_start(b, lay, wts):
    """Where a block's second half of rows starts: (middle, first), the support's rows from middle on and every other
    list's rows from first on (the support's row at middle; NONE when the support has no second half)."""
    kept = np.int64(wts.nnz[b])
    middle = kept // 2
    return middle, wts.support[lay.toff[b] + middle] if middle < kept else NONE


@njit(**NO_NRT, inline="always")
def _half_rows(h, b, lay, wts, stp):
    """Half h's rows: (s0, s1, m0, m1), its support rows s0 <= s < s1 and x_{t+1}'s rows m0 <= m < m1."""
    kept, k = np.int64(wts.nnz[b]), np.int64(stp.x_tp1.shape[0])
    middle, first = half_start(b, lay, wts)
    m_middle = np.int64(np.searchsorted(stp.x_tp1, first))
    if h == 0:
        return kept - kept, middle, k - k, m_middle
    return middle, kept, m_middle, k


@njit(**NO_NRT)
def walk_half(h, b, i0, i1, lay, wts, stp, scr):
    """Block b's demons i0 <= i < i1 walk half h of the rows (what they pay already in scr.ev: `owed_to_pay`)."""
    rows = _half_rows(h, b, lay, wts, stp)
    walk_rows(b, i0, i1, rows, lay, wts, stp, scr, scr.values[0] if h == 0 else scr.work[0], False)


@njit(**NO_NRT)
def join_halves(b, lay, wts, dem, cls, scr):
    """After both halves: each demon's value is the first half's sum plus the second's; then the TD errors."""
    db = lay.block_hi[b] - lay.block_lo[b]
    for i in range(db):
        u = at(i)
        scr.values[0, u] += scr.work[0, u]
    errors(b, db - db, db, lay, wts, dem, cls, scr)


@njit(**NO_NRT, inline="always")
def finish(b, lay, wts, dem, cls, stp, scr, along_x):
    """After every column: the traces move to e_t (the merge), the values at s_{t+1} take the owed update's part
    (owed[0] (e_t . x_{t+1}), one sum per class; `along_x`: - owed[1] (x_t . x_{t+1})) and become the demons'
    values and predictions; each class's continuation moves to s_{t+1}. `along_x` (true online TD): x_t's value on
    each support row is kept beside it for the next walk, and x_t's rows that the merge leaves without a trace pay
    - owed[1] x_t at once (the next walk would not reach them)."""
    lo, woff, voff, ncls, coff, toff = lay.block_lo[b], lay.woff[b], lay.voff[b], lay.ncls[b], lay.coff[b], lay.toff[b]
    db = lay.block_hi[b] - lo
    kept, dropped = merge(b, lay, wts, scr, stp.x_t, stp.v_t, 0, along_x)
    owed, fix = wts.owed[0, lo : lo + db], wts.owed[1, lo : lo + db]
    if along_x:
        for s in range(kept):
            wts.support_f[toff + s] = scr.rows_f[s]
        end = scr.rows.shape[0] - 1
        for k in range(dropped):
            base, f = at(woff + scr.rows[end - k] * db), scr.rows_f[end - k]
            for i in range(db):
                wts.theta[base + at(i)] -= fix[i] * f
    trace, values = wts.trace, scr.values
    x_tp1, v_tp1 = stp.x_tp1, stp.v_tp1
    shared = dot(stp.x_t, stp.v_t, x_tp1, v_tp1) if along_x else 0.0
    for c in range(ncls):
        e_dot_x = 0.0
        for j in range(x_tp1.shape[0]):
            e_dot_x += v_tp1[j] * np.float64(trace[voff + x_tp1[j] * ncls + c])
        c0, c1 = lay.class_lo[coff + c], lay.class_hi[coff + c]
        if along_x:
            for i in range(c0, c1):
                values[0, i] += owed[i] * e_dot_x - fix[i] * shared
        else:
            for i in range(c0, c1):
                values[0, i] += owed[i] * e_dot_x
    observe_range(b, 0, db, lay, dem, cls, values)
    for c in range(ncls):
        cls.gamma[coff + c] = cls.gamma_tp1[coff + c]


@njit(**NO_NRT)
def settle(b, lay, wts, scr, along_x):
    """Pay what block b owes (owed[0, d] times its class's trace on the support's rows; `along_x`: and - owed[1,
    d] times x_{t-1}'s value kept beside each); owe nothing more."""
    lo, woff, voff, ncls, coff, toff = lay.block_lo[b], lay.woff[b], lay.voff[b], lay.ncls[b], lay.coff[b], lay.toff[b]
    db = lay.block_hi[b] - lo
    owed, owed_fix = wts.owed[0, lo : lo + db], wts.owed[1, lo : lo + db]
    owing = False
    for i in range(db):
        owing = owing or owed[i] != 0.0 or (along_x and owed_fix[i] != 0.0)
    if not owing:
        return
    theta, trace, support, pay, fix = wts.theta, wts.trace, wts.support, scr.ev[0], scr.ev[1]
    owed_to_pay(b, db - db, db, lay, wts, scr, along_x)
    for s in range(wts.nnz[b]):  # (the walk's operations in its order, so that a call's length changes no bit)
        row = support[toff + s]
        base = at(woff + row * db)
        f = wts.support_f[toff + s] if along_x else 0.0
        if f != 0.0:
            scr.ev[2, 0] = f  # x_{t-1}'s value in the weights' dtype, as the walk pays it
            f = scr.ev[2, 0]
        for c in range(ncls):
            e = trace[voff + row * ncls + c]
            c0, c1 = lay.class_lo[coff + c], lay.class_hi[coff + c]
            if f != 0.0:
                _pay_with_fix(theta, base, pay, e, fix, f, c0, c1)
            elif e != 0.0:
                _pay(theta, base, pay, e, c0, c1)
    for i in range(db):
        owed[i] = 0.0
        owed_fix[i] = 0.0 if along_x else owed_fix[i]
