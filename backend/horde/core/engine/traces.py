"""The one trace kernel every learner shares: each class's trace decayed, x_t added, the support merged and cut.

A block keeps one trace column per trace class (demons with the same target policy, continuation, discount
and lambda, and for dutch traces the same alpha, have the same trace: DESIGN section 6). A trace is zero
outside the rows seen in the last few dozen steps; a block's support is the rows where any of its classes is
non-zero, sorted, and only those rows are touched by an update. Entries below the cut are set to zero
(`cut = 0` keeps every non-zero entry and equals `reference.py` to 1e-9).

What differs between learners is only what the trace decays by and what x_t adds (`decay[c]`, `add[c]`,
which each learner's `prepare` writes: gamma_t lambda rho_t and rho_t for TD and GTD, 1 for GQ, a dutch
trace's alpha (1 - rho gamma lambda e . x_t), emphatic TD's rho M_t).
"""

from __future__ import annotations

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

from horde.core.engine.layout import NO_NRT


@intrinsic
def _select_above_cut(typingctx, t, cut):
    """`above_cut` as LLVM's select."""

    def codegen(context, builder, signature, args):
        value, threshold = args
        fabs = builder.module.declare_intrinsic("llvm.fabs", [value.type])
        size = context.cast(builder, builder.call(fabs, [value]), signature.args[0], types.float64)
        keep = builder.fcmp_ordered(">=", size, context.cast(builder, threshold, signature.args[1], types.float64))
        return builder.select(keep, value, ir.Constant(value.type, 0.0))

    return t(t, cut), codegen


@njit(**NO_NRT, inline="always")
def above_cut(t, cut):
    """t where |t| >= cut, else 0 (a NaN too): `t if abs(t) >= cut else 0.0` as one select. Written in Python, the
    choice compiles to two branches, each storing its number, and a vectorized loop then stores through two masked
    stores (vmaskmovpd), which AMD's Zen cores run slowly: decaying a row of 2000 classes took 3.0 us, 0.6 as a
    select (docs/performance.md, "Masked stores on AMD's cores"). The same numbers to the bit; every cut of a trace
    entry takes it, so that the cut is written once."""
    return _select_above_cut(t, cut)  # type: ignore[call-arg]  # (mypy reads an intrinsic as its typing function)


@njit(**NO_NRT)
def decay_classes(tr, on_x, decay, add, cut, value):
    """New trace values of one row, one per class, in place (x_t's value on the row: `value`); entries below the
    cut become 0. Branch-free, so that it vectorizes. Returns whether any entry is left."""
    left = 0
    if on_x:
        for c in range(tr.shape[0]):
            t = tr[c] * decay[c] + add[c] * value
            t = above_cut(t, cut)
            tr[c] = t
            left += 1 if t != 0.0 else 0
    else:
        for c in range(tr.shape[0]):
            t = tr[c] * decay[c]
            t = above_cut(t, cut)
            tr[c] = t
            left += 1 if t != 0.0 else 0
    return left > 0


@njit(**NO_NRT, inline="always")
def _next_row(support, toff, old, i_old, x_t, v_t, j_new, shift):
    """The next row of the merge's walk over the old support (support[toff:][:old]) and x_t's rows shifted by
    `shift`, both sorted, from positions i_old and j_new: (the row, whether it is x_t's, x_t's value there or 0,
    the two positions past it)."""
    if j_new >= x_t.shape[0] or (i_old < old and support[toff + i_old] < shift + x_t[j_new]):
        return support[toff + i_old], False, 0.0, i_old + 1, j_new
    row = shift + x_t[j_new]
    return row, True, v_t[j_new], i_old + 1 if i_old < old and support[toff + i_old] == row else i_old, j_new + 1


@njit(**NO_NRT, inline="always")
def _new_support(b, toff, wts, rows, out):
    """Block b's support becomes rows[:out]."""
    for s in range(out):  # element by element: a slice copy may allocate (kernels run without NRT)
        wts.support[toff + s] = rows[s]
    wts.nnz[b] = out
    wts.touched[b] = out


@njit(**NO_NRT, inline="always")
def merge(b, lay, wts, scr, x_t, v_t, shift, keep_dropped):
    """Block b's traces for this step: e_c <- decay[c] e_c + add[c] x_t (x_t's rows shifted by `shift`, the
    action's block of state-action features), then the cut; x_t's rows merged into the support (both sorted).
    Nothing per demon is touched, so that the block's columns can then be learned apart.

    Returns (kept, dropped): the rows left with a trace, in `scr.rows[:kept]` in increasing order (the new
    support; `scr.rows_f` x_t's value on each, 0 off x_t; `scr.rows_e` the trace value of a one-class block);
    with `keep_dropped`, the rows of x_t left with none at the end of `scr.rows` (from its last entry down,
    their values in `scr.rows_f`): GTD's w still moves there.
    """
    toff, voff, ncls, cut = lay.toff[b], lay.voff[b], lay.ncls[b], lay.cut
    trace, support, rows, rows_e, rows_f = wts.trace, wts.support, scr.rows, scr.rows_e, scr.rows_f
    decay, add = scr.decay, scr.add
    k = x_t.shape[0]
    end = rows.shape[0] - 1
    old = wts.nnz[b]
    i_old = 0
    j_new = 0
    out = 0
    dropped = 0
    while i_old < old or j_new < k:
        row, on_x, value, i_old, j_new = _next_row(support, toff, old, i_old, x_t, v_t, j_new, shift)
        if ncls == 1:
            t = trace[voff + row] * decay[0]
            if on_x:
                t += add[0] * value
            trace[voff + row] = above_cut(t, cut)
            left = trace[voff + row] != 0.0
            rows_e[out] = trace[voff + row]  # the stored value
        else:
            left = decay_classes(trace[voff + row * ncls : voff + (row + 1) * ncls], on_x, decay, add, cut, value)
        if not left:
            if on_x and keep_dropped:
                rows[end - dropped] = row
                rows_f[end - dropped] = value
                dropped += 1
            continue
        rows[out] = row
        rows_f[out] = value
        out += 1
    _new_support(b, toff, wts, rows, out)
    return out, dropped


@njit(**NO_NRT)
def decay_two(tr0, tr1, on_x, decay, add, cut, value0, value1):
    """`decay_classes` on two rows at once (two memory streams in flight; each row's numbers as there): on_x 0 when
    neither row is x_t's, 1 the first, 2 the second, 3 both. Returns whether any entry is left on each row."""
    l0 = 0
    l1 = 0
    if on_x == 3:
        for c in range(tr0.shape[0]):
            t = tr0[c] * decay[c] + add[c] * value0
            t = above_cut(t, cut)
            tr0[c] = t
            l0 += 1 if t != 0.0 else 0
            u = tr1[c] * decay[c] + add[c] * value1
            u = above_cut(u, cut)
            tr1[c] = u
            l1 += 1 if u != 0.0 else 0
    elif on_x == 1:
        for c in range(tr0.shape[0]):
            t = tr0[c] * decay[c] + add[c] * value0
            t = above_cut(t, cut)
            tr0[c] = t
            l0 += 1 if t != 0.0 else 0
            u = tr1[c] * decay[c]
            u = above_cut(u, cut)
            tr1[c] = u
            l1 += 1 if u != 0.0 else 0
    elif on_x == 2:
        for c in range(tr0.shape[0]):
            t = tr0[c] * decay[c]
            t = above_cut(t, cut)
            tr0[c] = t
            l0 += 1 if t != 0.0 else 0
            u = tr1[c] * decay[c] + add[c] * value1
            u = above_cut(u, cut)
            tr1[c] = u
            l1 += 1 if u != 0.0 else 0
    else:
        for c in range(tr0.shape[0]):
            t = tr0[c] * decay[c]
            t = above_cut(t, cut)
            tr0[c] = t
            l0 += 1 if t != 0.0 else 0
            u = tr1[c] * decay[c]
            u = above_cut(u, cut)
            tr1[c] = u
            l1 += 1 if u != 0.0 else 0
    return l0 > 0, l1 > 0


@njit(**NO_NRT, inline="always")
def _place(row, on_x, value, left, keep_dropped, rows, rows_f, out, dropped):
    """A merged row into the new support (left) or among x_t's rows left without a trace: (out, dropped) after."""
    if left:
        rows[out] = row
        rows_f[out] = value
        return out + 1, dropped
    if on_x and keep_dropped:
        end = rows.shape[0] - 1
        rows[end - dropped] = row
        rows_f[end - dropped] = value
        return out, dropped + 1
    return out, dropped


@njit(**NO_NRT)
def merge_pairs(b, lay, wts, scr, x_t, v_t, shift, keep_dropped):
    """`merge` for a block of several classes, its rows decayed two at a time (`decay_two`): the same rows, numbers
    and order in `scr.rows`, `scr.rows_f` and the support. A row of 2000 classes (control GQ, each demon its
    own) is 16 KB, read and written once: one row at a time left memory idle between rows."""
    toff, voff, ncls, cut = lay.toff[b], lay.voff[b], lay.ncls[b], lay.cut
    trace, support, rows, rows_f = wts.trace, wts.support, scr.rows, scr.rows_f
    decay, add = scr.decay, scr.add
    k = x_t.shape[0]
    old = wts.nnz[b]
    i_old = 0
    j_new = 0
    out = 0
    dropped = 0
    waiting = False  # a row held for its pair (r0, its x_t flag and value)
    r0 = np.int64(0)
    on0 = False
    f0 = 0.0
    while i_old < old or j_new < k:
        row, on_x, value, i_old, j_new = _next_row(support, toff, old, i_old, x_t, v_t, j_new, shift)
        if not waiting:
            r0, on0, f0 = row, on_x, value
            waiting = True
            continue
        waiting = False
        left0, left1 = decay_two(trace[voff + r0 * ncls : voff + (r0 + 1) * ncls],
                                 trace[voff + row * ncls : voff + (row + 1) * ncls],
                                 (1 if on0 else 0) + (2 if on_x else 0), decay, add, cut, f0, value)  # fmt: skip
        out, dropped = _place(r0, on0, f0, left0, keep_dropped, rows, rows_f, out, dropped)
        out, dropped = _place(row, on_x, value, left1, keep_dropped, rows, rows_f, out, dropped)
    if waiting:
        left0 = decay_classes(trace[voff + r0 * ncls : voff + (r0 + 1) * ncls], on0, decay, add, cut, f0)
        out, dropped = _place(r0, on0, f0, left0, keep_dropped, rows, rows_f, out, dropped)
    _new_support(b, toff, wts, rows, out)
    return out, dropped


@njit(**NO_NRT, inline="always")
def union(b, lay, wts, scr, x_t, v_t, shift):
    """The rows of block b's support and x_t's (shifted by `shift`), merged in increasing order into `scr.rows[:n]`
    (x_t's value on each in `scr.rows_f`, 0 off x_t), each marked as holding no trace yet (`scr.rows_left`); the
    traces themselves untouched. For a learner that decays its traces in its own pass over these rows (GQ's
    own-value blocks, `gradient._classes_pass`) and then keeps the rows left with a trace (`keep_left`).
    Returns n."""
    toff, support = lay.toff[b], wts.support
    k = x_t.shape[0]
    old = wts.nnz[b]
    i_old = 0
    j_new = 0
    n = 0
    while i_old < old or j_new < k:
        row, _, value, i_old, j_new = _next_row(support, toff, old, i_old, x_t, v_t, j_new, shift)
        scr.rows[n] = row
        scr.rows_f[n] = value
        scr.rows_left[n] = 0
        n += 1
    return n


@njit(**NO_NRT, inline="always")
def keep_left(b, lay, wts, scr, n):
    """Block b's support becomes the rows of `scr.rows[:n]` (after `union`) that its pass left with a trace."""
    out = 0
    for s in range(n):
        if scr.rows_left[s] != 0:
            scr.rows[out] = scr.rows[s]
            out += 1
    _new_support(b, lay.toff[b], wts, scr.rows, out)


@njit(**NO_NRT)
def clear(b, lay, wts):
    """Block b's traces to zero (an episode starts): only its support rows are non-zero."""
    toff, voff, ncls = lay.toff[b], lay.voff[b], lay.ncls[b]
    for s in range(wts.nnz[b]):
        row = wts.support[toff + s]
        for c in range(ncls):
            wts.trace[voff + row * ncls + c] = 0.0
    wts.nnz[b] = 0


@njit(**NO_NRT)
def trace_dot(trace, voff, ncls, c, x, v):
    """Class c's trace . x over the rows x (values v)."""
    total = 0.0
    for j in range(x.shape[0]):
        total += v[j] * trace[voff + x[j] * ncls + c]
    return total
