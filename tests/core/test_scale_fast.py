"""The compiled Horde-scale engine (`scale_fast.FastScale`) equals the numpy path and the reference.

float64: to 1e-9 with or without the trace cut (both paths cut the same entries). float32 (weights and
traces stored in single precision, sums in double): within 2e-5 of the float64 reference, relative to
the size of the numbers, over hundreds of steps (docs/performance.md).
"""

from __future__ import annotations

import numpy as np
import pytest

from horde.core import scale
from horde.core.scale import Block, Layout
from horde.core.scale_fast import FastScale
from horde.core.scale_oracle import ReferenceDemons

from .test_scale import N_S, TOLERANCE, K, assert_equal_to_reference, mixed_blocks, random_stream


def assert_same_state(fast: FastScale, state: scale.ScaleState, tol: float, where: str) -> None:
    mine = fast.state()
    for name in ("theta", "w", "e"):
        for b, (a, c) in enumerate(zip(getattr(mine, name), getattr(state, name), strict=True)):
            np.testing.assert_allclose(a, c, rtol=0, atol=tol, err_msg=f"{name} of block {b} {where}")
    for name in ("prediction", "q", "pi", "gamma"):
        np.testing.assert_allclose(
            getattr(mine, name), getattr(state, name), rtol=0, atol=tol, err_msg=f"{name} {where}"
        )


@pytest.mark.parametrize("cut", [0.0, 1e-3], ids=["no cut", "cut 1e-3"])
def test_compiled_engine_equals_numpy_path_and_reference(cut: float) -> None:
    layout = Layout(tuple(mixed_blocks(np.random.default_rng(11))), N_S, K, cut=cut)
    x0, pi0, stream = random_stream(layout, 250, seed=12, revisit=0.5)
    fast = FastScale(layout)
    fast.observe(x0, pi0)
    state = scale.observe(layout, scale.zeros(layout), x0, pi0)
    ref = ReferenceDemons(layout)
    ref.observe(x0, pi0)
    for t, step in enumerate(stream):
        delta = fast.step(*step.args()).copy()
        state, numpy_delta = scale.step(layout, state, *step.args())
        np.testing.assert_allclose(delta, numpy_delta, rtol=0, atol=TOLERANCE, err_msg=f"delta at step {t}")
        np.testing.assert_allclose(fast.prediction, state.prediction, rtol=0, atol=TOLERANCE, err_msg=f"step {t}")
        if cut == 0.0:
            ref.step(*step.args())
        if t % 25 == 0 or t == len(stream) - 1:
            assert_same_state(fast, state, TOLERANCE, f"at step {t}")
            if cut == 0.0:
                assert_equal_to_reference(layout, fast.state(), ref, TOLERANCE, f"at step {t}")
    if cut > 0.0:
        assert fast.nnz.max() < layout.rows(layout.blocks[1]), "the cut kept some supports small"


def test_float32_stays_within_its_documented_tolerance() -> None:
    blocks = tuple(mixed_blocks(np.random.default_rng(13)))
    single = Layout(blocks, N_S, K, dtype=np.dtype(np.float32), cut=0.0)
    x0, pi0, stream = random_stream(single, 300, seed=14, revisit=0.5)
    fast = FastScale(single)
    fast.observe(x0, pi0)
    ref = ReferenceDemons(single)  # the plain equations in float64
    ref.observe(x0, pi0)
    for step in stream:
        fast.step(*step.args())
        ref.step(*step.args())
    assert fast.theta.dtype == np.float32
    scale_of = max(1.0, max(np.abs(t).max() for t in ref.theta))
    state = fast.state()
    for m, demon in enumerate(ref.demons):
        theta, w, _ = scale.demon_arrays(single, state, int(demon))
        np.testing.assert_allclose(theta, ref.theta[m], rtol=0, atol=2e-5 * scale_of)
        np.testing.assert_allclose(w, ref.w[m], rtol=0, atol=2e-5 * scale_of)
    np.testing.assert_allclose(fast.prediction, ref.prediction, rtol=0, atol=2e-5 * scale_of)


def test_state_out_and_back_in_continues_the_same_run() -> None:
    layout = Layout(tuple(mixed_blocks(np.random.default_rng(15))), N_S, K, cut=1e-3)
    x0, pi0, stream = random_stream(layout, 80, seed=16, revisit=0.5)
    fast = FastScale(layout)
    fast.observe(x0, pi0)
    for step in stream[:40]:
        fast.step(*step.args())
    moved = FastScale(layout)
    moved.load(fast.state())
    state = fast.state()
    for step in stream[40:]:
        fast.step(*step.args())
        moved.step(*step.args())
        state, _ = scale.step(layout, state, *step.args())
    assert_same_state(moved, fast.state(), 0.0, "after a load")
    assert_same_state(moved, state, TOLERANCE, "against the numpy path")


def test_a_new_episode_clears_the_compiled_traces() -> None:
    layout = Layout((Block("gq", np.full(3, 0.1), np.full(3, 0.01), 0.9, "softmax"),), N_S, K)
    x0, pi0, stream = random_stream(layout, 30, seed=17)
    fast = FastScale(layout)
    fast.observe(x0, pi0)
    for step in stream:
        fast.step(*step.args())
    assert fast.nnz.sum() > 0
    fast.observe(stream[-1].x_tp1)
    assert fast.nnz.sum() == 0 and not fast.trace.any()


def test_memory_and_traffic_figures_add_up() -> None:
    layout = Layout((Block("gtd", np.full(8, 0.1), np.full(8, 0.01), 0.9),), N_S, K)
    x0, pi0, stream = random_stream(layout, 20, seed=18)
    fast = FastScale(layout)
    fast.observe(x0, pi0)
    for step in stream:
        fast.step(*step.args())
    assert fast.memory_bytes() >= layout.weight_bytes() == 2 * N_S * 8 * 8
    rows = fast.touched.sum()
    assert rows > 0 and fast.traffic_bytes() >= 4 * rows * 64  # four passes over each support row
