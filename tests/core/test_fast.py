"""The compiled loop equals the numpy engine: same draws, same trajectory, same weights (to 1e-9)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from horde.core.simulation import Simulation
from horde.scenarios import load_scenario, scenario_dir

SCENARIOS = sorted(scenario_dir().glob("*.toml"))


def assert_same(fast: Simulation, slow: Simulation) -> None:
    a, b = fast.horde_state, slow.horde_state
    for fast_learner, slow_learner in zip(a.learners, b.learners, strict=True):
        np.testing.assert_allclose(fast_learner.theta, slow_learner.theta, rtol=0, atol=1e-9)
        np.testing.assert_allclose(fast_learner.w, slow_learner.w, rtol=0, atol=1e-9)
        np.testing.assert_allclose(fast_learner.e, slow_learner.e, rtol=0, atol=1e-9)
    for fast_metric, slow_metric in zip(a.metrics, b.metrics, strict=True):
        np.testing.assert_allclose(fast_metric.h, slow_metric.h, rtol=0, atol=1e-9)
        np.testing.assert_allclose(fast_metric.delta_e, slow_metric.delta_e, rtol=0, atol=1e-9)
        np.testing.assert_allclose(fast_metric.delta_mean, slow_metric.delta_mean, rtol=0, atol=1e-9)
    np.testing.assert_allclose(a.prediction, b.prediction, rtol=0, atol=1e-9)
    np.testing.assert_allclose(a.pi, b.pi, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(a.diverged, b.diverged)
    assert fast.position == slow.position
    assert fast.episode == slow.episode


@pytest.mark.parametrize("path", SCENARIOS, ids=[p.stem for p in SCENARIOS])
def test_fast_loop_equals_numpy_engine_step_by_step(path: Path) -> None:
    spec = load_scenario(path)
    fast = Simulation(spec, np.random.default_rng(11), engine="fast")
    slow = Simulation(spec, np.random.default_rng(11), engine="numpy")
    for step in range(600):
        a, b = fast.step(), slow.step()
        assert a == b, f"step {step}: {a} != {b}"
        if step % 50 == 0:
            assert_same(fast, slow)
    assert_same(fast, slow)
    assert fast.episode > 3, "the comparison crossed several episode boundaries"


def test_bulk_runs_equal_single_steps() -> None:
    spec = load_scenario(scenario_dir() / "experiment3.toml")
    bulk = Simulation(spec, np.random.default_rng(3))
    single = Simulation(spec, np.random.default_rng(3), engine="numpy")
    bulk.run(400)
    for _ in range(400):
        single.step()
    assert_same(bulk, single)
    assert bulk.total_steps == single.total_steps == 400


def test_test_runs_freeze_all_but_reset_demons() -> None:
    spec = load_scenario(scenario_dir() / "experiment3.toml")
    sims = [Simulation(spec, np.random.default_rng(5), engine=e) for e in ("fast", "numpy")]
    assert spec.protocol.test is not None
    learning = np.array([d.reset == "episode" for d in spec.demons])
    for sim in sims:
        sim.run(2000)
    before = sims[0].horde.weights(sims[0].horde_state, "base")
    results = [sim.run_episode(spec.protocol.test.behaviour, learning) for sim in sims]
    assert results[0] == results[1]
    assert_same(*sims)
    np.testing.assert_array_equal(sims[0].horde.weights(sims[0].horde_state, "base"), before)


def test_state_round_trips_through_load() -> None:
    spec = load_scenario(scenario_dir() / "classroom-offpolicy.toml")
    sim = Simulation(spec, np.random.default_rng(1))
    sim.run(500)
    saved_state, saved_world = sim.horde_state, sim.world_state
    saved_rng = sim.rng.bit_generator.state
    sim.run(300)
    after = sim.predictions()
    resumed = Simulation(spec, np.random.default_rng(99))
    resumed.world_state = saved_world
    resumed.horde_state = saved_state
    resumed.rng.bit_generator.state = saved_rng
    resumed.run(300)
    assert resumed.predictions() == pytest.approx(after, abs=1e-12)
