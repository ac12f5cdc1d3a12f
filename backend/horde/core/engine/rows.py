"""The row primitives every learner's kernel shares: sums of weight rows, sparse dot products, the TD error.

A block's weights are `[rows, Db]` row-major (feature-major): the weights of one feature for all the block's
demons are one contiguous row, so a sum over active features `theta . x` for every demon is a sum of whole
rows, and a kernel that learns a run of columns (demons i0 <= i < i1, `step.columns_on_threads`) reads a
run of each row. Features are sparse: sorted distinct indices `x` with values `v`.

Offsets into the flat buffers are unsigned (`at`): numba wraps a signed index that may be negative, and that
check turns a row loop's loads into gathers (2 to 8 times slower); with unsigned offsets the loops load
contiguous vectors.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from horde.core.engine.layout import NO_NRT


@njit(**NO_NRT, inline="always")
def at(offset):
    """An offset into a flat buffer as an unsigned integer (never wrapped around: see the module)."""
    return np.uint64(offset)


@njit(**NO_NRT, inline="always")
def td_error(r_tp1, z_tp1, gamma_tp1, v_tp1, v_t):
    """delta_t = r_tp1 + (1 - gamma_tp1) z_tp1 + gamma_tp1 v_tp1 - v_t: the one TD error of every learner."""
    return r_tp1 + (1.0 - gamma_tp1) * z_tp1 + gamma_tp1 * v_tp1 - v_t


@njit(**NO_NRT)
def sum_rows(flat, start, x, v, db, acc):
    """acc += sum_j v[j] * row x[j] of the [n, db] array at flat[start:], four rows at a time.

    acc may be a run of columns: start then points at its first column, and db stays the row length. A
    value of 1 multiplies exactly, so binary features give the sums of the rows bit for bit."""
    width = acc.shape[0]
    k = x.shape[0]
    j = 0
    while j + 4 <= k:
        o0 = at(start + x[j] * db)
        o1 = at(start + x[j + 1] * db)
        o2 = at(start + x[j + 2] * db)
        o3 = at(start + x[j + 3] * db)
        v0, v1, v2, v3 = v[j], v[j + 1], v[j + 2], v[j + 3]
        for i in range(width):
            u = at(i)
            acc[i] += ((v0 * flat[o0 + u] + v1 * flat[o1 + u]) + v2 * flat[o2 + u]) + v3 * flat[o3 + u]
        j += 4
    while j < k:
        o0 = at(start + x[j] * db)
        v0 = v[j]
        for i in range(width):
            acc[i] += v0 * flat[o0 + at(i)]
        j += 1


@njit(**NO_NRT)
def read_range(woff, db, actions, n_s, theta, x, v, i0, i1, out):
    """Values at the active state features (x, v) of the block at woff ([actions n_s, db] weights) for its
    demons i0 <= i < i1: out[a, i0:i1] for every action a of action values, or a = 0."""
    for a in range(actions):
        acc = out[a, i0:i1]
        acc[:] = 0.0
        sum_rows(theta, woff + a * n_s * db + i0, x, v, db, acc)


@njit(**NO_NRT)
def dot(x, vx, y, vy):
    """x . y for two sparse vectors (sorted distinct indices with values)."""
    total = 0.0
    i = 0
    j = 0
    while i < x.shape[0] and j < y.shape[0]:
        if x[i] < y[j]:
            i += 1
        elif y[j] < x[i]:
            j += 1
        else:
            total += vx[i] * vy[j]
            i += 1
            j += 1
    return total


@njit(**NO_NRT)
def square(v):
    """sum_j v[j]^2: x . x of a sparse vector with values v."""
    total = 0.0
    for j in range(v.shape[0]):
        total += v[j] * v[j]
    return total


@njit(**NO_NRT)
def pay_and_read(theta, start, x_t, v_t, x_tp1, v_tp1, db, owed, acc):
    """theta pays `owed` on the rows of x_t (times x_t's value there), then acc = theta . x_tp1: one walk over
    the union of the two sorted lists. As in `sum_rows`, acc may be a run of columns (start at its first
    column, db the row length); `owed` (the same run) is 0 afterwards."""
    width = acc.shape[0]
    for i in range(width):
        acc[i] = 0.0
    nt = x_t.shape[0]
    nn = x_tp1.shape[0]
    j_t = 0
    j_n = 0
    while j_t < nt or j_n < nn:
        on_t = j_t < nt and (j_n >= nn or x_t[j_t] <= x_tp1[j_n])
        on_n = j_n < nn and (j_t >= nt or x_tp1[j_n] <= x_t[j_t])
        row = x_t[j_t] if on_t else x_tp1[j_n]
        u = at(start + row * db)
        if not on_t:
            m_n = v_tp1[j_n]
            for i in range(width):
                acc[i] += m_n * theta[u + at(i)]
        elif not on_n:
            m_t = v_t[j_t]
            for i in range(width):
                theta[u + at(i)] -= m_t * owed[i]
        else:
            m_t, m_n = v_t[j_t], v_tp1[j_n]
            for i in range(width):
                value = theta[u + at(i)] - m_t * owed[i]
                theta[u + at(i)] = value
                acc[i] += m_n * value
        j_t += 1 if on_t else 0
        j_n += 1 if on_n else 0
    for i in range(width):
        owed[i] = 0.0


@njit(**NO_NRT)
def pay_and_read_four(theta, start, stride, x_t, v_t, x_tp1, v_tp1, db, owed, acc):
    """`pay_and_read` for four actions at once, action a's rows at start + a stride (its owed[a] and acc[a]: runs
    of columns, as there): one walk, and each row's loop over the four actions' rows together (four memory streams
    in flight instead of one). Each action's numbers come from the same operations in the same order."""
    o0, o1, o2, o3 = owed
    c0, c1, c2, c3 = acc
    width = c0.shape[0]
    for i in range(width):
        c0[i] = 0.0
        c1[i] = 0.0
        c2[i] = 0.0
        c3[i] = 0.0
    nt = x_t.shape[0]
    nn = x_tp1.shape[0]
    j_t = 0
    j_n = 0
    while j_t < nt or j_n < nn:
        on_t = j_t < nt and (j_n >= nn or x_t[j_t] <= x_tp1[j_n])
        on_n = j_n < nn and (j_t >= nt or x_tp1[j_n] <= x_t[j_t])
        row = x_t[j_t] if on_t else x_tp1[j_n]
        u0 = at(start + row * db)
        u1 = at(start + stride + row * db)
        u2 = at(start + 2 * stride + row * db)
        u3 = at(start + 3 * stride + row * db)
        if not on_t:
            m_n = v_tp1[j_n]
            for i in range(width):
                c0[i] += m_n * theta[u0 + at(i)]
                c1[i] += m_n * theta[u1 + at(i)]
                c2[i] += m_n * theta[u2 + at(i)]
                c3[i] += m_n * theta[u3 + at(i)]
        elif not on_n:
            m_t = v_t[j_t]
            for i in range(width):
                theta[u0 + at(i)] -= m_t * o0[i]
                theta[u1 + at(i)] -= m_t * o1[i]
                theta[u2 + at(i)] -= m_t * o2[i]
                theta[u3 + at(i)] -= m_t * o3[i]
        else:
            m_t, m_n = v_t[j_t], v_tp1[j_n]
            for i in range(width):
                t0 = theta[u0 + at(i)] - m_t * o0[i]
                t1 = theta[u1 + at(i)] - m_t * o1[i]
                t2 = theta[u2 + at(i)] - m_t * o2[i]
                t3 = theta[u3 + at(i)] - m_t * o3[i]
                theta[u0 + at(i)] = t0
                theta[u1 + at(i)] = t1
                theta[u2 + at(i)] = t2
                theta[u3 + at(i)] = t3
                c0[i] += m_n * t0
                c1[i] += m_n * t1
                c2[i] += m_n * t2
                c3[i] += m_n * t3
        j_t += 1 if on_t else 0
        j_n += 1 if on_n else 0
    for i in range(width):
        o0[i] = 0.0
        o1[i] = 0.0
        o2[i] = 0.0
        o3[i] = 0.0


@njit(**NO_NRT)
def spread(trace, start, ncls, class_lo, class_hi, coff, i0, i1, out):
    """out[i - i0] = the trace value (trace[start + c]) of the class of demon i, for i0 <= i < i1."""
    for c in range(ncls):
        c0 = max(class_lo[coff + c], i0)
        c1 = min(class_hi[coff + c], i1)
        if c0 < c1:
            out[c0 - i0 : c1 - i0] = trace[start + c]


@njit(**NO_NRT, inline="always")
def add_row(i0, i1, base, theta, acc, value):
    """acc += value * the weight row at base, columns i0 <= i < i1 (values at x_tp1, read row by row).

    A binary feature's row (value 1) is added without the multiplication, the same numbers: the row was just
    written by the walk and is in cache, so the loop is bound by its arithmetic, and numba does not fuse a
    multiply and an add (docs/performance.md, issue 29)."""
    if value == 1.0:
        for i in range(i0, i1):
            u = at(i)
            acc[u] += theta[base + u]
    else:
        for i in range(i0, i1):
            u = at(i)
            acc[u] += value * theta[base + u]


@njit(**NO_NRT, inline="always")
def walk(rows, kept, s, x_t, v_t, j, x_tp1, v_tp1, m):
    """The next row of a walk over the support (rows[:kept]), x_t and x_tp1, all sorted, from positions s, j
    and m: (the row, or -1 at the end; whether it is in the support; x_t's and x_tp1's values on it, 0
    where it is not theirs; the three positions past it)."""
    row = -1
    if s < kept:
        row = rows[s]
    if j < x_t.shape[0] and (row < 0 or x_t[j] < row):
        row = x_t[j]
    if m < x_tp1.shape[0] and (row < 0 or x_tp1[m] < row):
        row = x_tp1[m]
    in_support = s < kept and rows[s] == row
    on_x = 0.0
    if j < x_t.shape[0] and x_t[j] == row:
        on_x = v_t[j]
        j += 1
    on_next = 0.0
    if m < x_tp1.shape[0] and x_tp1[m] == row:
        on_next = v_tp1[m]
        m += 1
    return row, in_support, on_x, on_next, s + (1 if in_support else 0), j, m


FLOAT32_FOLD = 1e-20  # a scale kept beside float32 vectors is folded back in below this (see `fold_floor`)


@njit(**NO_NRT)
def fold_floor(vectors, float64_floor):
    """The scale below which a lazily kept scale (TDRC's and the original GTD's s of h = s w, RUPEE's of u) is
    folded back into the per-weight `vectors` it divides: `float64_floor` for float64 vectors, FLOAT32_FOLD for
    float32. A vector is kept divided by its scale, so it grows as the scale shrinks: float32's largest number
    is 3.4e38, and a scale of 1e-40 made TDRC's w and RUPEE's u infinite; above 1e-20 a value up to 1e18 fits."""
    return FLOAT32_FOLD if vectors.itemsize == 4 else float64_floor
