"""RUPEE and UDE of every demon, compiled: `horde.core.metrics`' equations with the average of delta e scaled lazily.

After a group learned a step, each of its demons folds its TD error and trace into RUPEE's h and average of
delta e (u) and into UDE's averages. u decays by one number per group (`Metrics.scale`), so that its decay
does not touch every row at every step; hu[d] keeps sum_rows h * u of each demon up to date as rows change,
so that RUPEE is read in O(D). Each demon's numbers touch only its own column of h and u (`columns`), so a
block of at least PARALLEL_MIN demons splits its demons over threads (`step.columns_on_threads`), the same
numbers to the last bit whatever the count.
"""

from __future__ import annotations

import math

from numba import njit

from horde.core.engine.layout import NO_NRT
from horde.core.engine.rows import at, fold_floor
from horde.core.metrics import RUPEE_ALPHA_H, RUPEE_BETA, UDE_BETA

SCALE_FLOOR = 1e-200  # RUPEE's lazily decayed average is folded back in below this scale


@njit(**NO_NRT)
def start_group(g, grp, lay, met):
    """The averaging rates of group g's step (the unbiased start of White 2015), its lazy decay, and what every
    demon's columns take: met.coef = (alpha_h, the gain of delta e into u, UDE's rate)."""
    met.tau[g, 0] = (1 - RUPEE_BETA) * met.tau[g, 0] + RUPEE_BETA
    met.tau[g, 1] = (1 - UDE_BETA) * met.tau[g, 1] + UDE_BETA
    beta = RUPEE_BETA / met.tau[g, 0]
    decayed = met.scale[g] * (1.0 - beta)
    # fold the scale back in (the first step's beta is 1): one pass over the group
    if decayed < fold_floor(met.u, SCALE_FLOOR):
        for b in range(grp.block_lo[g], grp.block_hi[g]):
            woff, size = lay.woff[b], lay.rows[b] * (lay.block_hi[b] - lay.block_lo[b])
            for j in range(woff, woff + size):
                met.u[j] *= decayed
            for s in range(lay.block_lo[b], lay.block_hi[b]):
                met.hu[s] *= decayed
        decayed = 1.0
    met.scale[g] = decayed
    met.coef[0] = RUPEE_ALPHA_H / grp.k[g]
    met.coef[1] = beta / met.scale[g]
    met.coef[2] = UDE_BETA / met.tau[g, 1]


@njit(**NO_NRT)
def columns(b, i0, i1, lay, wts, dem, met, stp):
    """RUPEE's h, u and h . u and UDE's averages of block b's demons i0 <= i < i1 after their step (x_t: the
    step's stp.x_t): only their columns of h, u and of hx (h . x_t at [i], delta at [db + i]) are touched."""
    lo, woff, toff = lay.block_lo[b], lay.woff[b], lay.toff[b]
    voff, ncls, coff = lay.voff[b], lay.ncls[b], lay.coff[b]
    db = lay.block_hi[b] - lo
    h, u, hu, hx, stats = met.h, met.u, met.hu, met.hx, met.stats
    alpha_h, gain, b_ude = met.coef[0], met.coef[1], met.coef[2]
    x_t, v_t = stp.x_t, stp.v_t
    shift = stp.action * stp.n_s if lay.actions[b] > 1 else 0
    for i in range(i0, i1):
        hx[i] = 0.0
    for j in range(x_t.shape[0]):
        start = at(woff + (shift + x_t[j]) * db)
        value = v_t[j]
        for i in range(i0, i1):
            hx[i] += value * h[start + at(i)]
    for i in range(i0, i1):
        d = dem.delta[lo + i]
        if not math.isfinite(d):
            d = 0.0
        stats[lo + i, 0] = (1 - b_ude) * stats[lo + i, 0] + b_ude * d
        stats[lo + i, 1] = (1 - b_ude) * stats[lo + i, 1] + b_ude * d * d
        stats[lo + i, 2] = (1 - b_ude) * stats[lo + i, 2] + b_ude * abs(d)
        hx[db + i] = d  # delta, 0 where not finite
    for s in range(wts.nnz[b]):  # the trace's support: a class's demons are a run of columns sharing its entry
        row = wts.support[toff + s]
        start = at(woff + row * db)
        for c in range(ncls):
            ev = wts.trace[voff + row * ncls + c]
            if ev == 0.0:  # (h and u would not change)
                continue
            for i in range(max(i0, lay.class_lo[coff + c]), min(i1, lay.class_hi[coff + c])):
                d = hx[db + i]
                k = start + at(i)
                h0, u0 = h[k], u[k]
                h1, u1 = h0 + alpha_h * d * ev, u0 + gain * d * ev
                h[k], u[k] = h1, u1
                hu[lo + i] += h1 * u1 - h0 * u0
    for j in range(x_t.shape[0]):
        start = at(woff + (shift + x_t[j]) * db)
        value = v_t[j]
        for i in range(i0, i1):
            k = start + at(i)
            h0 = h[k]
            h1 = h0 - alpha_h * hx[i] * value
            h[k] = h1
            hu[lo + i] += (h1 - h0) * u[k]
