"""Scenarios in float32 (issue 27, what must hold 2): their results within the tolerances float64's are held to.

Every shipped scenario in both dtypes is `python -m benchmarks.float32_scenarios` (minutes: docs/performance.md,
"float32 across the scenarios", has its table); here a cheap subset runs in float32 through the command's own
judges: a chain at its TD fixed point, Baird's counterexample (TD diverges, the gradient learners stay bounded),
the recorded MountainCar log and experiment3's greedy test runs, one each of the Gymnasium, off-policy, stream
and grid (thesis) paths.
"""

from __future__ import annotations

import numpy as np
import pytest
from benchmarks import float32_scenarios as f32

from horde.core.simulation import Simulation
from horde.scenarios import find_scenario, list_scenarios
from horde.worlds.gymnasium import GymAgent
from horde.worlds.records import RecordLearner


def test_every_shipped_scenario_has_a_float32_criterion() -> None:
    assert {s.name for s in list_scenarios()} == set(f32.CRITERIA)


@pytest.mark.parametrize("name", ["boyan-chain", "baird", "mountaincar-log", "experiment3"])
def test_a_scenario_in_float32_keeps_its_float64_tolerance(name: str) -> None:
    spec = f32.with_dtype(find_scenario(name), "float32")
    if spec.world.kind == "stream":
        learner = RecordLearner(spec).loop
    elif spec.world.kind == "grid":
        learner = Simulation(spec).learner
    else:
        learner = GymAgent(spec, np.random.default_rng(0)).learner
    assert learner.engine.t.wts.theta.dtype == np.float32, "the run is not in float32"
    row = f32.check(name, ("float32",))
    judged = row.results["float32"]
    assert judged.holds, (name, judged.figure)


def test_rupee_stays_finite_in_a_long_float32_run() -> None:
    """A live run keeps its metrics on: experiment1 in float32 for 10,000 steps, RUPEE and UDE finite."""
    sim = Simulation(f32.with_dtype(find_scenario("experiment1"), "float32"))
    sim.with_metrics = True
    sim.run(10_000)
    engine = sim.learner.engine
    assert np.isfinite(engine.rupee()).all() and np.isfinite(engine.ude()).all(), engine.rupee()
