"""The one learner interface (`core/learner.py`) and its divergence rule, the same for every source.

A demon whose TD error, prediction or action values go beyond MAX_MAGNITUDE is frozen by the compiled step
(tests/server/test_divergence.py); one whose weights do, while its prediction still reads small, by the
learner's scan of every weight, every `scan_interval` steps, whether a stream feeds it or the grid world.
"""

from __future__ import annotations

import numpy as np

from horde.core.engine.layout import MAX_MAGNITUDE
from horde.core.horde import Horde
from horde.core.learner import Learner, LearnerState
from horde.core.simulation import Simulation
from horde.spec import RunSpec

STREAM = {"kind": "stream", "actions": 2, "sensors": [{"name": "a", "low": 0, "high": 3}]}
DEMONS = [
    {"name": "calm", "learner": "gtd", "policy": "uniform", "cumulant": 0.1},
    {"name": "wild", "learner": "td", "policy": "uniform", "cumulant": 0.1},
]


def spec(world: dict | None = None) -> RunSpec:
    features = {"kind": "table", "sensor": "a", "table": [[0], [1], [2], [3]]} if world is None else {"kind": "grid"}
    return RunSpec.model_validate({"world": world or STREAM, "features": features, "demons": DEMONS})


def plant(learner: Learner, name: str, row: int, value: float) -> None:
    """One weight of one demon set to `value`, on a feature the agent does not stand on."""
    state = learner.state()
    b, col = learner.horde.locate(name)
    theta = [t.copy() for t in state.horde.theta]
    theta[b][row, col] = value
    learner.load(LearnerState(state.horde._replace(theta=tuple(theta)), state.adaptive))


def test_a_weight_beyond_the_bound_freezes_its_demon_alone() -> None:
    learner = Learner(Horde(spec()))
    learner.observe(np.array([0.0]))
    learner.learn(np.array([[1.0], [0.0]]), [0, 1], [0.5, 0.5])
    assert not learner.scan_weights().any()
    plant(learner, "wild", 3, 2 * MAX_MAGNITUDE)  # state 3: never visited, the prediction stays small
    assert abs(learner.readout().prediction[1]) < 1.0 and not learner.readout().diverged.any()
    assert learner.scan_weights().tolist() == [False, True]
    out = learner.readout()
    assert out.diverged.tolist() == [False, True]
    state = learner.horde_state()
    assert not learner.horde.weights(state, "wild").any(), "frozen with its weights set to 0"
    before = learner.horde.weights(state, "calm").copy()
    learner.learn(np.array([[2.0], [1.0]]), [0, 1], [0.5, 0.5])
    state = learner.horde_state()
    assert not learner.horde.weights(state, "wild").any(), "and it learns no more"
    assert np.abs(learner.horde.weights(state, "calm") - before).max() > 0, "the other goes on"


def test_the_scan_runs_by_itself_every_scan_interval_steps_for_a_stream_and_the_grid() -> None:
    learner = Learner(Horde(spec()))
    assert learner.scan_interval == 1000  # the least: a small Horde's scan costs little
    learner.scan_interval = 4
    learner.observe(np.array([0.0]))
    plant(learner, "wild", 3, np.inf)
    learner.learn(np.array([[1.0], [0.0], [1.0]]), [0, 1, 0], [0.5, 0.5, 0.5])
    assert not learner.readout().diverged.any(), "3 steps: no scan yet"
    learner.learn(np.array([1.0]), [1], [0.5])
    assert learner.readout().diverged.tolist() == [False, True], "the fourth step's scan froze it"
    sim = Simulation(spec(world={"width": 500, "height": 500, "step": 100}))
    sim.learner.scan_interval = 10
    plant(sim.learner, "wild", 24, np.nan)
    sim.run(9)
    assert not sim.readout().diverged.any()
    sim.run(1)
    assert sim.readout().diverged.tolist() == [False, True]


def test_state_and_load_round_trip() -> None:
    one, two = Learner(Horde(spec())), Learner(Horde(spec()))
    for learner in (one, two):
        learner.observe(np.array([0.0]))
    one.learn(np.array([[1.0], [2.0], [0.0]]), [0, 1, 1], [0.5, 0.5, 0.5])
    two.load(one.state(), one.sensors)
    assert np.array_equal(two.sensors, one.sensors)
    for learner in (one, two):
        learner.learn(np.array([[3.0], [1.0]]), [0, 0], [0.5, 0.5])
    np.testing.assert_array_equal(one.readout().prediction, two.readout().prediction)
    for a, b in zip(one.horde_state().theta, two.horde_state().theta, strict=True):
        np.testing.assert_array_equal(a, b)
