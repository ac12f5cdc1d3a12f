"""The learners that need less tuning on a run's threads: the same numbers whatever the count.

Blocks of true online TD(lambda), emphatic TD(lambda) and TD(lambda) with Autostep / TIDBD of at least
`engine.layout.PARALLEL_MIN` demons split their demons into runs of columns learned by threads
(`engine.step.columns_on_threads`); each column goes through the same operations in the same order
whatever the split (and Autostep's column chunks), so every weight, trace, per-weight step size,
normaliser and prediction must be equal to the last bit on 1, 2 and 3 threads. A few demons of the
threaded run are also replayed into the oracle (`reference.py`), which has no threads at all.
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np
import pytest

from horde.core.engine.layout import PARALLEL_MIN
from horde.core.simulation import Simulation
from horde.spec import RunSpec

from .test_threads import on_1_2_3_threads, threaded_run_against_the_oracle, tiles_spec


def onl(sim: Simulation) -> Any:
    """What the learners beyond the gradient family keep (`engine.layout.Online`)."""
    return sim.learner.engine.t.onl


D = PARALLEL_MIN + 13  # demons per block: over the threshold, not a multiple of the column alignment
DISCOUNTS = (0, 0.5, 0.8, 0.9, 0.95)
SENSORS = ("x", "y", "bump", "reward", "in:goal", "in:crit", "color:lamp")
POLICIES = ([0.4, 0.1, 0.1, 0.4], [0.1, 0.2, 0.3, 0.4], [0.25, 0.25, 0.25, 0.25])


def online_spec(demons: int = D) -> RunSpec:
    """Five blocks past the threshold: true online TD about three fixed target policies at two alphas and
    five discounts (30 dutch-trace classes), ETD about the three policies, Autostep on-policy at five
    discounts with two meta steps (one past the polynomial exp's range) and demons reset every episode,
    TIDBD about the three policies, and true online GTD about the three policies at five discounts (its w
    pass moving two rows at once and reading the next step's sums on each thread's columns); with episode
    ends."""
    out: list[dict[str, Any]] = []
    for i in range(demons):
        cumulant = {"mul": [{"sensor": SENSORS[i % 7]}, 1 + i // 35]}
        fixed = {"kind": "fixed", "probabilities": POLICIES[i % 3]}
        out += [
            {"name": f"to{i}", "learner": "true_online_td", "discount": DISCOUNTS[i % 5], "policy": fixed,
             "alpha": (0.1, 0.05)[i % 2], "cumulant": cumulant},
            {"name": f"etd{i}", "learner": "etd", "discount": 0.9, "lambda": 0.7, "policy": fixed,
             "cumulant": {"sensor": SENSORS[i % 7]}},
            {"name": f"auto{i}", "learner": "td", "step_size": "autostep", "lambda": 0.8, "policy": "uniform",
             "discount": DISCOUNTS[i % 5], "meta_step": (0.01, 0.2)[i % 2], "alpha": (0.5, 0.1)[i % 2],
             "reset": "episode" if i % 3 == 0 else "never", "cumulant": cumulant},
            {"name": f"tidbd{i}", "learner": "td", "step_size": "tidbd", "lambda": 0.5, "discount": 0.8,
             "policy": fixed, "meta_step": 0.01, "cumulant": {"sensor": SENSORS[i % 7]}},
            {"name": f"togtd{i}", "learner": "true_online_gtd", "discount": DISCOUNTS[i % 5], "policy": fixed,
             "alpha": 0.05, "alpha_w": 0.01, "cumulant": cumulant},
        ]  # fmt: skip
    return tiles_spec(out)


@pytest.fixture(scope="module")
def spec() -> RunSpec:
    return online_spec()


@pytest.mark.slow
def test_thread_count_does_not_change_a_single_bit(spec: RunSpec) -> None:
    one, others = on_1_2_3_threads(spec)  # and adaptive demons reset at the episodes' ends
    scales = onl(one).scale
    assert scales.min() < 1.0, "Autostep's bound divided some step sizes (the effective step size passed 1)"
    for other in others:
        for field in ("v_old", "cls_f", "step_a", "step_v", "scale", "step_max", "trace2", "w_read"):
            np.testing.assert_array_equal(getattr(onl(one), field), getattr(onl(other), field), field)
        np.testing.assert_array_equal(one.effective_step_sizes(), other.effective_step_sizes())
    assert numba.threading_layer() in ("tbb", "omp", "workqueue"), "a threading layer ran the blocks"


@pytest.mark.slow
def test_threaded_blocks_equal_the_oracle(spec: RunSpec) -> None:
    """Twelve demons spread over the blocks, replayed into the oracle from the threaded run's own transitions (TIDBD,
    without Autostep's bound, may diverge on these cumulants, and the engine then freezes the demon)."""
    live = threaded_run_against_the_oracle(spec, 12)
    assert live >= 10, "most of the picked demons stayed finite: the comparison covered them"


@pytest.mark.slow
def test_autostep_walks_alike_fused_or_not() -> None:
    """An Autostep block whose demons' effective step sizes stay well below 1 (alpha 0.1, mu 0.01): the runs
    of columns whose M provably stays 1 take the fused walk (meta step and update together), the others the
    two passes (on this spec: the fused walk on most steps, measured by marking it); the numbers are the same
    bits on 1, 2 and 3 threads whichever each run took, and the step sizes did adapt."""
    demons = [{"name": f"auto{i}", "learner": "td", "step_size": "autostep", "lambda": 0.8, "policy": "uniform",
               "discount": DISCOUNTS[i % 5], "meta_step": 0.01, "alpha": 0.1 if i % 4 else 0.4,
               "cumulant": {"mul": [{"sensor": SENSORS[i % 7]}, 1 + i // 35]}} for i in range(D)]  # fmt: skip
    one, others = on_1_2_3_threads(tiles_spec(demons))
    for other in others:
        for field in ("step_a", "step_v", "scale", "step_max"):
            np.testing.assert_array_equal(getattr(onl(one), field), getattr(onl(other), field), field)
    moved = np.abs(one.effective_step_sizes() - np.where(np.arange(D) % 4, 0.1, 0.4))
    assert moved.max() > 1e-6, "the step sizes adapted"
