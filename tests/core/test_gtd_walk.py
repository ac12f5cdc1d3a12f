"""GTD's walk (`gtd_pass.walk_half`, both halves) against the plain sums, on the engine's own arrays: it pays what each
demon owes on every row of the last support and of x_t (theta: K k - C f, w: B o - D p; `gtd_pass`) and reads theta .
x_{t+1}, w . x_t and w . e_t from the paid rows, whether it takes the rows that pay four, two or one at a time (it
holds them until there are four). x_t and x_{t+1} are chosen so that every case occurs: x_t's rows inside and outside
the support, x_{t+1}'s rows between them that are read only, and 0 to 3 rows left over at each half's end."""

from __future__ import annotations

import numpy as np
import pytest

from horde.core.engine.layout import Step
from horde.core.engine.traces import above_cut
from horde.core.learners import gtd_pass

from .test_class_runs import nexting_engine


def _rows(support: np.ndarray, rows: int, extra: int, rng: np.random.Generator) -> tuple[np.ndarray, ...]:
    """x_t (a third of the support's rows and `extra` rows outside it) and x_{t+1} (a third of the support's rows,
    some of x_t's outside rows and ten rows in neither), sorted, with their values."""
    outside = np.setdiff1d(np.arange(rows), support)
    picks = rng.permutation(outside.shape[0])
    x_t = np.sort(np.concatenate([support[::3], outside[picks[: extra + 4]]])).astype(np.int64)
    x_tp1 = np.sort(np.concatenate([support[1::3], outside[picks[2 : extra + 14]]])).astype(np.int64)
    return x_t, rng.uniform(0.5, 1.5, x_t.shape[0]), x_tp1, rng.uniform(0.5, 1.5, x_tp1.shape[0])


@pytest.mark.timeout(300)
@pytest.mark.parametrize("dtype", ["float64", "float32"])
@pytest.mark.parametrize("form", [gtd_pass.FOLLOWS_DELTA, gtd_pass.FOLLOWS_W])
def test_the_walk_pays_and_reads_rows_as_the_plain_sums(dtype: str, form: int) -> None:
    t = nexting_engine("gtd", dtype).learner.engine.t
    lay, wts, scr = t.lay, t.wts, t.scr
    lo, hi, woff, voff, toff = (int(a[0]) for a in (lay.block_lo, lay.block_hi, lay.woff, lay.voff, lay.toff))
    db, ncls, rows, kept = hi - lo, int(lay.ncls[0]), int(lay.rows[0]), int(wts.nnz[0])
    assert ncls == 5 and kept > 100
    support = wts.support[toff : toff + kept].copy()
    dtype_of = wts.theta.dtype
    theta = wts.theta[woff : woff + rows * db].reshape(rows, db)
    w = wts.w[woff : woff + rows * db].reshape(rows, db)
    trace = wts.trace[voff : voff + rows * ncls].reshape(rows, ncls)
    of_class = np.repeat(np.arange(ncls), lay.class_hi[:ncls] - lay.class_lo[:ncls])
    theta_0, w_0 = theta.copy(), w.copy()
    rng = np.random.default_rng(1)
    for extra in range(4):  # rows that pay: one more each time, so that each half ends with 0 to 3 held
        theta[:], w[:] = theta_0, w_0
        owed = rng.normal(0.0, 0.1, (5, db))
        owed[gtd_pass.OWED_M if form == gtd_pass.FOLLOWS_DELTA else gtd_pass.OWED_A] = 0.0
        wts.owed[:5, lo:hi] = owed
        x_t, v_t, x_tp1, v_tp1 = _rows(support, rows, extra, rng)

        # The plain sums, in the weights' dtype as the walk pays (x_{t-1}'s value on each support row kept beside it)
        pay_k = (owed[gtd_pass.OWED_A] + owed[gtd_pass.OWED_M]).astype(dtype_of)
        pay_b, pay_c, pay_d = (owed[r].astype(dtype_of) for r in (gtd_pass.OWED_B, gtd_pass.OWED_C, gtd_pass.OWED_D))
        paying = np.union1d(support, x_t)
        f = np.zeros(rows)
        f[x_t] = v_t
        p = np.zeros(rows)
        p[support] = wts.support_f[toff : toff + kept]
        g = np.zeros(rows)
        g[x_tp1] = v_tp1
        f32, p32, g32 = f.astype(dtype_of), p.astype(dtype_of), g.astype(dtype_of)
        o = trace[paying][:, of_class]
        k = o if form == gtd_pass.FOLLOWS_DELTA else p32[paying][:, None]
        theta_paid, w_paid = theta_0.copy(), w_0.copy()
        theta_paid[paying] = theta_0[paying] + pay_k * k - pay_c * f32[paying][:, None]
        w_paid[paying] = w_0[paying] + pay_b * o - pay_d * p32[paying][:, None]
        decay, add = scr.decay[:ncls][of_class], scr.add[:ncls][of_class]
        e_t = np.array([[above_cut(o[r, i] * decay[i] + add[i] * f[row], lay.cut) for i in range(db)]
                        for r, row in enumerate(paying)]).astype(dtype_of)  # fmt: skip
        value = g32 @ theta_paid.astype(np.float64)
        w_x = f32[paying] @ w_paid[paying].astype(np.float64)
        w_e = np.einsum("ri,ri->i", e_t.astype(np.float64), w_paid[paying].astype(np.float64))

        step = Step(x_t, v_t, x_tp1, v_tp1, 0, 0.25, 0)
        gtd_pass.before_halves(0, lay, wts, scr)
        gtd_pass.walk_half(0, 0, 0, db, lay, wts, step, scr, form)
        gtd_pass.walk_half(1, 0, 0, db, lay, wts, step, scr, form)

        np.testing.assert_array_equal(theta, theta_paid)  # each weight paid once, in the same operations
        np.testing.assert_array_equal(w, w_paid)
        tolerance = 1e-12 if dtype == "float64" else 1e-5  # (float32: sums over SUM_ROWS rows in float32)
        sums = scr.work[1:4, :db] + scr.work[4:7, :db]
        for name, got, want in zip(("theta . x_t+1", "w . x_t", "w . e_t"), sums, (value, w_x, w_e), strict=True):
            np.testing.assert_allclose(got, want, rtol=tolerance, atol=tolerance, err_msg=f"{name}, extra {extra}")
