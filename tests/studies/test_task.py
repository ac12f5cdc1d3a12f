"""One study task: its measurements against exact answers and Monte-Carlo truth, and its determinism."""

from __future__ import annotations

import numpy as np
import pytest

from horde.core.evaluate import exact
from horde.core.simulation import Simulation
from horde.scenarios import find_scenario
from horde.spec import RunSpec
from horde.studies.spec import MeasureSpec
from horde.studies.task import checkpoint_episodes, has_exact_answers, run_task


@pytest.fixture(scope="module")
def classroom() -> RunSpec:
    spec = find_scenario("classroom-offpolicy")
    return spec.model_copy(update={"protocol": spec.protocol.model_copy(update={"episodes": 300})})


def test_checkpoints_start_before_learning_and_end_at_the_last_episode() -> None:
    assert checkpoint_episodes(100, 4) == [0, 25, 50, 75, 100]
    assert checkpoint_episodes(3, 10) == [0, 1, 2, 3]


def test_before_learning_the_error_is_the_rms_of_the_exact_answer(classroom: RunSpec) -> None:
    # zero weights predict 0 everywhere, so the RMSE is the RMS of the exact values: computed here apart
    out = run_task(classroom, 0, MeasureSpec(checkpoints=3, demons=["steps_random", "goal_random"]))
    assert out["truth"] == "exact" and out["episodes"] == [0, 100, 200, 300]
    sim = Simulation(classroom, np.random.default_rng(0))
    for name in ("steps_random", "goal_random"):
        values = exact(sim.horde, sim.horde_state, name).value
        row = out["demons"][name]
        assert row["error"][0] == pytest.approx(np.sqrt(np.mean(values**2)), rel=1e-12)
        assert row["scale"][0] == row["error"][0]
        assert row["prediction"][0] == 0.0
    # the random walk's expected steps to the end are tens of steps; learning brings the error down
    steps = out["demons"]["steps_random"]
    assert steps["scale"][0] > 20
    assert steps["error"][-1] < 0.8 * steps["error"][0]


def test_the_final_error_equals_a_hand_run_of_the_same_seed(classroom: RunSpec) -> None:
    out = run_task(classroom, 4, MeasureSpec(checkpoints=2, demons=["goal_northeast"]))
    sim = Simulation(classroom, np.random.default_rng([classroom.seed, 4]))
    for _ in range(300):
        sim.run_episode()
    lattice = exact(sim.horde, sim.horde_state, "goal_northeast")
    predicted = sim.horde.forward(sim.horde_state, lattice.x, lattice.y).prediction[
        :, sim.horde.index["goal_northeast"]
    ]
    assert out["demons"]["goal_northeast"]["error"][-1] == pytest.approx(
        float(np.sqrt(np.mean((predicted - lattice.value) ** 2))), rel=1e-12
    )


def test_checkpoints_do_not_change_the_learning_trajectory(classroom: RunSpec) -> None:
    few = run_task(classroom, 1, MeasureSpec(checkpoints=1))
    many = run_task(classroom, 1, MeasureSpec(checkpoints=6))
    assert few["steps"] == many["steps"]
    for name in few["demons"]:
        assert few["demons"][name]["error"][-1] == many["demons"][name]["error"][-1]


def test_different_runs_learn_from_different_streams(classroom: RunSpec) -> None:
    a, b = (run_task(classroom, run, MeasureSpec(checkpoints=1)) for run in (0, 1))
    assert a["steps"] != b["steps"]


def test_a_noisy_world_is_measured_against_monte_carlo(classroom: RunSpec) -> None:
    noisy = classroom.model_copy(update={"world": classroom.world.model_copy(update={"noise": 5.0})})
    assert not has_exact_answers(noisy, ["goal_random"])
    out = run_task(noisy, 0, MeasureSpec(checkpoints=1, demons=["goal_random"], rollouts=200, episodes=None))
    assert out["truth"] == "monte_carlo"
    row = out["demons"]["goal_random"]
    # before learning the prediction is 0, so the error is the truth's size: a goal probability in (0, 1)
    assert row["error"][0] == row["scale"][0] and 0.1 < row["scale"][0] < 0.9
    assert row["error"][-1] < row["error"][0]


def test_unknown_measured_demons_are_refused(classroom: RunSpec) -> None:
    with pytest.raises(ValueError, match="nobody"):
        run_task(classroom, 0, MeasureSpec(demons=["nobody"]))


def test_a_control_protocol_counts_where_its_test_runs_end() -> None:
    spec = find_scenario("experiment3")
    spec = spec.model_copy(update={"protocol": spec.protocol.model_copy(update={"episodes": 20})})
    out = run_task(spec, 0, MeasureSpec(checkpoints=1))
    counts = out["counts"]
    assert sum(counts.values()) == spec.protocol.test.runs  # type: ignore[union-attr]
    assert out["truth"] == "monte_carlo"  # an indicator's colour is hidden state: no exact answers
