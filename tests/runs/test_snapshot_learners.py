"""Snapshots of runs whose demons keep state beyond weights and traces: the per-weight step sizes of
autostep and tidbd, true online TD's v_old, true online GTD's extra traces, emphatic TD's followon trace.

Run A n + m steps; capture at n, restore, run m steps: every prediction, weight and step size equal to
the last bit (the round trip through the stored bytes included).
"""

from __future__ import annotations

import numpy as np
import pytest
from benchmarks import workloads
from tests.server.helpers import make_spec

from horde.runs.errors import SpecError
from horde.runs.run_setup import new_simulation
from horde.runs.snapshot import Snapshot, capture, from_bytes, restore, to_bytes
from horde.spec import RunSpec

DEMONS = [
    {"name": "auto", "learner": "td", "step_size": "autostep", "cumulant": 1, "discount": 0.9, "alpha": 0.3},
    {"name": "idbd", "learner": "td", "step_size": "tidbd", "cumulant": 1, "discount": 0.8, "alpha": 0.01},
    {"name": "online", "learner": "true_online_td", "cumulant": 1, "discount": 0.9},
    {"name": "online_gtd", "learner": "true_online_gtd", "cumulant": {"sensor": "y"}, "discount": 0.9},
    {"name": "emphatic", "learner": "etd", "cumulant": 1, "discount": 0.7, "alpha": 0.01},
    {"name": "plain", "learner": "gtd", "cumulant": 1, "discount": 0.9},
]


@pytest.fixture(scope="module")
def spec() -> RunSpec:
    return RunSpec.model_validate(make_spec(demons=DEMONS, behaviour="uniform", features={"kind": "stripes"}))


def test_step_sizes_round_trip_and_the_restored_run_continues_bit_for_bit(spec: RunSpec) -> None:
    sim = new_simulation(spec)
    sim.run(1500)
    snapshot = from_bytes(to_bytes(capture(sim, spec, "paused", None, None)))
    tuned = {name: sim.step_sizes(name) for name in ("auto", "idbd")}
    assert all(np.ptp(sizes) > 0 for sizes in tuned.values()), "the adaptive demons tuned their step sizes"

    restored = restore(snapshot).sim
    for name, sizes in tuned.items():
        np.testing.assert_array_equal(restored.step_sizes(name), sizes, err_msg=f"{name}'s step sizes")
    np.testing.assert_array_equal(restored.effective_step_sizes(), sim.effective_step_sizes())

    sim.run(1500)
    restored.run(1500)
    np.testing.assert_array_equal(restored.readout().prediction, sim.readout().prediction)
    for a, b in zip(restored.thetas(), sim.thetas(), strict=True):
        np.testing.assert_array_equal(a, b)
    for name in ("auto", "idbd"):
        np.testing.assert_array_equal(restored.step_sizes(name), sim.step_sizes(name))


def test_true_online_gtd_restored_goes_on_to_the_last_bit_over_hundreds_of_rows() -> None:
    """True online GTD's step takes w . e_grad and w . x_t from what the last step's w pass read; a restored run
    has no such pass behind it and reads them afresh (`true_online._read_w`), over the same rows in the same
    order, so it goes on to the same bits. Nexting's tiles, 457 of 6065 features active at a time: sums over
    hundreds of rows, whose order shows in their last bits."""
    spec = workloads.spec("nexting", 40, "true_online_gtd")
    sim = new_simulation(spec)
    sim.run(300)
    restored = restore(from_bytes(to_bytes(capture(sim, spec, "paused", None, None)))).sim
    sim.run(200)
    restored.run(200)
    np.testing.assert_array_equal(restored.readout().prediction, sim.readout().prediction)
    for a, b in zip(restored.thetas(), sim.thetas(), strict=True):
        np.testing.assert_array_equal(a, b)
    engines = (restored.learner.engine, sim.learner.engine)
    for b in range(len(sim.learner.engine.horde.blocks)):
        np.testing.assert_array_equal(*(engine.weights(engine.t.wts.w, b) for engine in engines))


def test_a_wrong_step_size_array_is_422_naming_the_field(spec: RunSpec) -> None:
    sim = new_simulation(spec)
    sim.run(10)
    document = capture(sim, spec, "paused", None, None).model_dump(by_alias=True)
    assert document["online"] is not None and "step_a" in document["online"]
    document["online"]["step_a"]["shape"] = [1]
    document["online"]["step_a"]["data"] = ""
    with pytest.raises(SpecError) as info:
        restore(Snapshot.model_validate(document))
    assert info.value.problems[0].loc == ("body", "online", "step_a"), info.value


def test_a_demon_joining_leaves_the_others_step_sizes_tuned(spec: RunSpec) -> None:
    sim = new_simulation(spec)
    sim.run(1500)
    tuned = {name: sim.step_sizes(name) for name in ("auto", "idbd")}
    joined = RunSpec.model_validate(
        {**spec.model_dump(by_alias=True), "demons": [*DEMONS, {"name": "late", "learner": "td", "cumulant": 1}]}
    )
    after = sim.with_spec(joined)
    for name, sizes in tuned.items():
        np.testing.assert_array_equal(after.step_sizes(name), sizes, err_msg=f"{name}'s step sizes")
    start = float(joined.learning.alpha)
    assert np.all(after.step_sizes("late") == start / 5), "the new constant demon takes alpha over the active count"


def test_runs_without_such_learners_keep_their_snapshots_as_they_were() -> None:
    plain = RunSpec.model_validate(make_spec(demons=[DEMONS[-1]], behaviour="uniform"))
    sim = new_simulation(plain)
    sim.run(10)
    assert capture(sim, plain, "paused", None, None).online is None  # no step-size arrays the size of theta
