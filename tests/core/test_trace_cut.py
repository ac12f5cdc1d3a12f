"""The trace cut as the kernels take it (`engine.traces.above_cut`, `decay_classes`, `decay_two`): an entry whose
magnitude is below the cut becomes 0, one at or above it stays, a NaN becomes 0; checked by hand at the edges and
against numpy's form on whole rows, in both dtypes."""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

from horde.core.engine.traces import above_cut, decay_classes, decay_two

pytestmark = pytest.mark.timeout(300)


@njit(cache=True)
def _above_cut(t: float, cut: float) -> float:
    return above_cut(t, cut)


@njit(cache=True)
def _above_cut32(t: np.float32, cut: float) -> np.float32:
    return above_cut(t, cut)


CASES = [  # (t, cut, kept): worked by hand
    (1e-8, 1e-8, 1e-8),  # at the cut: kept
    (-1e-8, 1e-8, -1e-8),
    (9.99e-9, 1e-8, 0.0),  # below it: 0
    (-9.99e-9, 1e-8, 0.0),
    (0.5, 0.0, 0.5),
    (5e-324, 0.0, 5e-324),  # cut 0 keeps every entry, the smallest subnormal too
    (np.inf, 1e-8, np.inf),
    (-np.inf, 1e-8, -np.inf),
    (np.nan, 1e-8, 0.0),  # a NaN is not at or above any cut
    (np.nan, 0.0, 0.0),
]


@pytest.mark.parametrize(("t", "cut", "kept"), CASES)
def test_above_cut_by_hand(t: float, cut: float, kept: float) -> None:
    assert _above_cut(t, cut) == kept
    cut32 = float(np.float32(cut))  # the cut where the float32 entry lies (np.float32(1e-8) is below 1e-8)
    assert _above_cut32(np.float32(t), cut32) == np.float32(kept)


def test_above_cut_keeps_the_sign_of_a_kept_zero() -> None:
    """-0.0 at cut 0 is kept as it is, as the Python form `t if abs(t) >= cut else 0.0` keeps it."""
    assert np.signbit(_above_cut(-0.0, 0.0))
    assert not np.signbit(_above_cut(-1e-12, 1e-8))  # a cut entry is +0.0


def numpy_decay(tr: np.ndarray, decay: np.ndarray, add: np.ndarray, value: float | None, cut: float) -> np.ndarray:
    t = tr.astype(np.float64) * decay + (add * value if value is not None else 0.0)
    return np.where(np.abs(t) >= cut, t, 0.0).astype(tr.dtype)


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_a_row_of_classes_decays_and_is_cut_as_numpy_says(dtype: type) -> None:
    """2003 classes (a vector loop and its remainder), a third of them pushed just under or onto the cut."""
    rng = np.random.default_rng(5)
    cut = 1e-6
    n = 2003
    decay = rng.uniform(0.5, 1.0, n)
    add = rng.uniform(0.0, 2.0, n)
    tr = (rng.normal(size=n) * 1e-5).astype(dtype)
    near = rng.choice(n, n // 3, replace=False)
    tr[near] = (cut / decay[near] * rng.choice([0.999, 1.0, 1.001], near.size)).astype(dtype)
    for on_x, value in [(False, None), (True, 2e-7)]:  # x_t adds less than the cut to some
        row = tr.copy()
        left = decay_classes(row, on_x, decay, add, cut, value if on_x else 0.0)
        want = numpy_decay(tr, decay, add, value, cut)
        np.testing.assert_array_equal(row, want)
        assert left == bool(np.any(want != 0.0))
        assert np.any(want == 0.0) and np.any(want != 0.0), "the rows cross the cut"
    for on_x in range(4):
        rows = tr.copy(), tr[::-1].copy()
        values = (2e-7 if on_x & 1 else None, -3e-7 if on_x & 2 else None)
        lefts = decay_two(rows[0], rows[1], on_x, decay, add, cut, values[0] or 0.0, values[1] or 0.0)
        for k in range(2):
            want = numpy_decay((tr, tr[::-1])[k], decay, add, values[k], cut)
            np.testing.assert_array_equal(rows[k], want)
            assert lefts[k] == bool(np.any(want != 0.0))


def test_a_row_cut_whole_says_nothing_is_left() -> None:
    row = np.full(9, 1e-9)
    assert not decay_classes(row, False, np.ones(9), np.ones(9), 1e-8, 0.0)
    assert not np.any(row)
