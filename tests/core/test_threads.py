"""A run's threads: the same numbers whatever their count, and cores yielded to the other runs.

Blocks of at least `engine.layout.PARALLEL_MIN` demons split their demons into runs of columns learned by threads
(`engine.step.columns_on_threads`; a TD or GTD block walks two fixed halves of its rows, a thread each); every number is
computed by the same operations in the same order whatever the split, so the state after many steps must be equal to the
last bit for 1, 2 and 3 threads. `horde.core.threads` gives each run the process's cores divided among the runs
learning.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from typing import Any

import numba
import numpy as np
import pytest

from horde.core import learners, threads
from horde.core.engine.layout import PARALLEL_MIN
from horde.core.reference import ReferenceHorde
from horde.core.simulation import Simulation
from horde.spec import RunSpec

from .test_engine_vs_reference import run_spec
from .test_fast import assert_same

D = PARALLEL_MIN + 13  # demons per block: over the threshold, and not a multiple of the column alignment


DISCOUNTS = (0, 0.5, 0.8, 0.9, 0.95)


def wide_spec() -> RunSpec:
    """Three blocks past the threshold: TD on-policy at five discounts (five shared traces), GTD about
    three fixed target policies, and GQ control demons (a trace of their own each), with episode ends."""
    sensors = ["x", "y", "bump", "reward", "in:goal", "in:crit", "color:lamp"]
    policies = ([0.4, 0.1, 0.1, 0.4], [0.1, 0.2, 0.3, 0.4], [0.25, 0.25, 0.25, 0.25])
    demons: list[dict[str, Any]] = []
    for i in range(D):
        demons.append({"name": f"td{i}", "learner": "td", "policy": "uniform", "discount": DISCOUNTS[i % 5],
                       "cumulant": {"mul": [{"sensor": sensors[i % len(sensors)]}, 1 + i // 35]}})  # fmt: skip
        demons.append({"name": f"gtd{i}", "learner": "gtd", "discount": 0.9, "lambda": 0.7,
                       "policy": {"kind": "fixed", "probabilities": policies[i % 3]},
                       "cumulant": {"sensor": sensors[i % len(sensors)]}})  # fmt: skip
        demons.append({"name": f"gq{i}", "learner": "gq", "discount": 0.8,
                       "policy": {"kind": "softmax", "temperature": 0.5 + i % 4},
                       "cumulant": {"sensor": sensors[i % len(sensors)]}})  # fmt: skip
    return tiles_spec(demons)


def tiles_spec(demons: list[dict[str, Any]]) -> RunSpec:
    """The engine tests' world under a uniform behaviour with these demons over 4 x 4 tiles, 4 tilings."""
    data = run_spec("uniform").model_dump(by_alias=True)
    data.update(demons=demons, features={"kind": "tiles", "tilings": 4, "tiles": 4})
    return RunSpec.model_validate(data)


@pytest.fixture(scope="module")
def spec() -> RunSpec:
    return wide_spec()


def run_with(spec: RunSpec, count: int, steps: int = 300) -> Simulation:
    sim = Simulation(spec, np.random.default_rng(11))
    sim.threads = count
    sim.run(steps)
    return sim


def on_1_2_3_threads(spec: RunSpec) -> tuple[Simulation, list[Simulation]]:
    """The spec run on one thread and on 2 and 3, every block past the threshold, episodes ended: the run
    on one thread and the others, whose weights, traces and predictions are its to the last bit."""
    one = run_with(spec, 1)
    assert one.threads == 1
    assert {b.size for b in one.horde.blocks} == {D}, "every block is past the threshold"
    assert one.episode >= 3, "episodes ended (traces cleared, a new start observed)"
    others = [run_with(spec, count) for count in (2, 3)]
    for count, other in zip((2, 3), others, strict=True):
        assert other.threads == count
        assert_same(one.horde_state, other.horde_state)
        assert one.position == other.position
    return one, others


def threaded_run_against_the_oracle(spec: RunSpec, count: int, steps: int = 120, threads: int = 2) -> int:
    """`count` demons spread over the spec's blocks, replayed into ReferenceHorde (which has no threads) from a run
    on `threads` threads: predictions equal to 1e-9 with the trace cut at 0, at every step. How many of them the oracle
    kept finite at the end (a demon the oracle lets diverge, the engine freezes: README)."""
    sim = Simulation(spec, np.random.default_rng(5), cut=0.0)
    sim.threads = threads
    picked = np.linspace(0, len(spec.demons) - 1, count).astype(np.int64)
    data = spec.model_dump(by_alias=True)
    data["demons"] = [data["demons"][i] for i in picked]
    reference = ReferenceHorde(RunSpec.model_validate(data))
    names = sim.world.sensor_names
    reference.observe(*sim.position, dict(zip(names, sim.start_sensors.tolist(), strict=True)))
    live = np.ones(count, bool)
    for step in range(steps):
        result = sim.step()
        sensors = sim.sensors
        reference.learn(result.action, sim.behaviour_probability, float(sensors[0]), float(sensors[1]),
                        dict(zip(names, sensors.tolist(), strict=True)), result.terminated)  # fmt: skip
        if result.done:
            reference.observe(*sim.position, dict(zip(names, sim.start_sensors.tolist(), strict=True)))
        ours = sim.prediction_array()[picked]
        theirs = np.array([reference.demons[spec.demons[i].name].prediction for i in picked])
        live = np.isfinite(theirs)
        np.testing.assert_allclose(ours[live], theirs[live], rtol=1e-9, atol=1e-9, err_msg=f"step {step}")
    return int(live.sum())


@pytest.mark.slow
def test_thread_count_does_not_change_a_single_bit(spec: RunSpec) -> None:
    one, others = on_1_2_3_threads(spec)
    for other in others:
        np.testing.assert_array_equal(one.readout().rupee, other.readout().rupee)
        np.testing.assert_array_equal(one.readout().ude, other.readout().ude)
    # a threading layer started: the blocks were split over threads (it raises if none ever ran)
    assert numba.threading_layer() in ("tbb", "omp", "workqueue")


@pytest.mark.slow
def test_thread_count_does_not_change_a_single_bit_in_float32(spec: RunSpec) -> None:
    """float32's walks split alike: TD's pays and reads two rows at once, GTD's sums a few rows in float32 before it
    adds them into its float64 sums (`gtd_pass.SUM_ROWS`), at the same rows whatever the columns."""
    data = spec.model_dump(by_alias=True)
    data["demons"] = [demon for demon in data["demons"] if demon["learner"] != "gq"]
    data["learning"]["dtype"] = "float32"
    one, _ = on_1_2_3_threads(RunSpec.model_validate(data))
    assert all(theta.dtype == np.float32 for theta in one.horde_state.theta)


@pytest.mark.slow
def test_threaded_blocks_equal_the_oracle(spec: RunSpec) -> None:
    """The wide TD and GTD blocks walk their rows in two halves (`td_pass.walk_half`, `gtd_pass.walk_half`) and add
    the halves' sums after; GQ's block splits its columns. Four threads: each half of the rows in two runs of columns,
    the split that a machine of four cores takes (the thread-count tests cover one to three). 15 demons of the three
    blocks against the oracle."""
    halves = {
        block.learner for block in Simulation(spec).horde.blocks if learners.walks_in_halves(block.code, block.size)
    }
    assert halves == {"td", "gtd"}
    assert threaded_run_against_the_oracle(spec, 15, threads=4) == 15


def gtd_family_spec() -> RunSpec:
    """Three wide blocks of GTD's kernel in its other forms, about three fixed target policies: TDRC (its h kept
    scaled), GTD2 (theta follows w) and the original GTD (theta follows u, kept scaled; lambda 0)."""
    sensors = ["x", "y", "bump", "reward", "in:goal", "in:crit", "color:lamp"]
    policies = ([0.4, 0.1, 0.1, 0.4], [0.1, 0.2, 0.3, 0.4], [0.25, 0.25, 0.25, 0.25])
    demons: list[dict[str, Any]] = []
    for i in range(D):
        policy = {"kind": "fixed", "probabilities": policies[i % 3]}
        cumulant = {"mul": [{"sensor": sensors[i % len(sensors)]}, 1 + i // 100]}
        demons.append({"name": f"tdrc{i}", "learner": "tdrc", "discount": DISCOUNTS[i % 5], "lambda": 0.7,
                       "policy": policy, "cumulant": cumulant})  # fmt: skip
        demons.append({"name": f"gtd2_{i}", "learner": "gtd2", "discount": 0.9, "lambda": 0.5, "policy": policy,
                       "cumulant": cumulant})  # fmt: skip
        demons.append({"name": f"gtd1_{i}", "learner": "gtd1", "discount": 0.8, "policy": policy,
                       "cumulant": cumulant})  # fmt: skip
    return tiles_spec(demons)


@pytest.mark.slow
def test_gtd_kernels_other_forms_walk_in_halves_alike() -> None:
    """TDRC's, GTD2's and the original GTD's wide blocks walk GTD's rows in halves, each form with what it owes and
    how it keeps w: the same bits on 1, 2 and 3 threads, and 9 demons of the three equal to the oracle on two."""
    spec = gtd_family_spec()
    one, _ = on_1_2_3_threads(spec)
    assert all(learners.walks_in_halves(block.code, block.size) for block in one.horde.blocks)
    assert threaded_run_against_the_oracle(spec, 9) == 9


def test_small_hordes_take_one_thread() -> None:
    sim = Simulation(run_spec("uniform"))
    sim.threads = 4
    assert sim.threads == 1, "no block is wide enough to split"


@pytest.fixture
def budget_of_two() -> Iterator[None]:
    threads.set_budget(2)
    try:
        yield
    finally:
        threads.set_budget(None)


def test_runs_share_the_budget(budget_of_two: None, spec: RunSpec) -> None:
    sim = Simulation(spec)
    assert threads.running_runs() == 0
    assert sim.threads == threads.share(1) == 2, "alone, a run takes every core"
    with threads.running():
        assert sim.threads == 1, "with another run learning, it takes its half"
        with threads.running():
            assert threads.share() == 1, "never less than one thread"
    assert sim.threads == 2, "and takes them back when the other run stops"
    sim.threads = 3
    assert sim.threads == 3, "a count set by hand wins"
    sim.threads = None
    assert sim.threads == 2


@pytest.mark.slow
def test_a_learning_run_is_counted_while_it_steps(budget_of_two: None, spec: RunSpec) -> None:
    """Two simulations in two threads: while one steps (inside Simulation.run), the other gets one thread."""
    busy = Simulation(spec)
    other = Simulation(spec)
    stop = threading.Event()

    def learn() -> None:
        while not stop.is_set():
            busy.run(5)

    worker = threading.Thread(target=learn, daemon=True)
    worker.start()
    try:
        seen = set()
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and 1 not in seen:
            seen.add(other.threads)
            time.sleep(0.001)
        assert 1 in seen, f"the other run never yielded a core while one was learning (saw {seen})"
    finally:
        stop.set()
        worker.join(60)
    assert not worker.is_alive(), "the learning thread stopped within 60 s"
    assert threads.running_runs() == 0 and other.threads == 2


def test_worker_processes_share_the_cores(budget_of_two: None) -> None:
    assert threads.worker_budget(2) == 1  # 2 cores over 2 workers (and one thread after a fork under OpenMP)
    assert threads.worker_budget(1) == (2 if threads.LAYER == "tbb" else 1)
