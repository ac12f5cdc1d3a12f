"""The engine's input path from outside (core/external.py) against the grid world's own compiled loop.

Feeding `Learner` the transitions that the grid loop produced (the sensors after each move, the
action, b(a_t | s_t), terminated / truncated, and each episode's first sensors) must give the grid loop's
numbers exactly: one engine, two ways in. Then N actions (not four), and the record checks.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from tests.core.test_fast import assert_same

from horde.core.horde import Horde
from horde.core.learner import ExternalRecordError, Learner
from horde.core.simulation import Simulation
from horde.spec import RunSpec


def grid_spec() -> RunSpec:
    """A grid world with a terminal, a zone, slip; features tiled over sensors; every learner and policy kind."""
    return RunSpec.model_validate(
        {
            "world": {
                "width": 400, "height": 400, "step": 100, "slip": 0.2, "max_steps": 30, "start": [0, 0, 400, 200],
                "regions": [
                    {"name": "goal", "kind": "terminal", "rect": [300, 300, 400, 400], "reward": 1},
                    {"name": "zone", "kind": "zone", "rect": [0, 200, 200, 400]},
                ],
            },
            "features": {"kind": "sensors", "tilings": 4, "tiles": 4, "size": 200,
                         "sensors": [{"sensor": "x", "low": 0, "high": 400}, {"sensor": "y", "low": 0, "high": 400},
                                     {"sensor": "in:zone", "low": 0, "high": 1}]},
            "behaviour": {"kind": "epsilon_greedy", "demon": "control", "epsilon": 0.3},
            "demons": [
                {"name": "control", "learner": "gq", "policy": "greedy", "cumulant": {"sensor": "reward"},
                 "outcome": 0},
                {"name": "zone_td", "learner": "td", "policy": {"of": "control"}, "cumulant": {"sensor": "in:zone"},
                 "discount": 0.8},
                {"name": "up_gtd", "learner": "gtd", "policy": {"kind": "fixed", "probabilities": [0.7, 0.1, 0.1, 0.1]},
                 "cumulant": {"sensor": "y"}, "discount": 0.5},
                {"name": "steps_gq", "learner": "gq", "policy": "uniform", "cumulant": 1},
                {"name": "reads", "learner": "td", "policy": "uniform", "cumulant": {"prediction": "zone_td"},
                 "discount": 0.5},
            ],
            "seed": 4,
        }
    )  # fmt: skip


def adaptive_spec() -> RunSpec:
    """The grid spec with the learners of adaptive_kernels.py (which `_step` skips) beside the others."""
    body = grid_spec().model_dump(mode="json", exclude_none=True)
    body["demons"] += [
        {"name": "online", "learner": "true_online_td", "policy": "uniform", "cumulant": {"sensor": "in:zone"},
         "discount": 0.8},
        {"name": "online_gtd", "learner": "true_online_gtd", "policy": {"of": "control"}, "cumulant": 1,
         "discount": 0.5},
        {"name": "emphatic", "learner": "etd", "policy": {"of": "control"}, "cumulant": {"sensor": "y"},
         "discount": 0.5},
        {"name": "auto", "learner": "td", "step_size": "autostep", "policy": "uniform", "cumulant": 1,
         "discount": 0.8},
        {"name": "tidbd", "learner": "td", "step_size": "tidbd", "policy": "uniform", "cumulant": {"sensor": "x"},
         "discount": 0.5},
    ]  # fmt: skip
    return RunSpec.model_validate(body)


@pytest.mark.parametrize("make_spec", [grid_spec, adaptive_spec], ids=["learners", "adaptive learners"])
def test_external_transitions_equal_the_grid_loop(make_spec: Callable[[], RunSpec]) -> None:
    spec = make_spec()
    sim = Simulation(spec, np.random.default_rng(11))
    external = Learner(Horde(spec))
    external.observe(sim.start_sensors)
    ends = 0
    for _ in range(600):
        step = sim.step()
        external.learn(sim.sensors, [step.action], [sim.behaviour_probability], step.terminated, step.truncated)
        if step.done:
            ends += 1
            external.observe(sim.start_sensors)
    assert ends > 10, "the stream should cross many episode ends, by termination and by truncation"
    assert_same(external.horde_state(), sim.horde_state)
    np.testing.assert_array_equal(external.prediction(), sim.prediction_array())


def test_a_batch_of_rows_equals_one_row_at_a_time() -> None:
    spec = grid_spec()
    rng = np.random.default_rng(2)
    sensors = np.column_stack([rng.uniform(0, 400, 200), rng.uniform(0, 400, 200), np.zeros(200),
                               np.arange(200), np.zeros(200), rng.integers(0, 2, (200, 2)), np.zeros(200)])  # fmt: skip
    actions = rng.integers(0, 4, 200)
    probs = np.full(200, 0.25)
    one, batch = Learner(Horde(spec)), Learner(Horde(spec))
    one.observe(sensors[0])
    batch.observe(sensors[0])
    for t in range(1, 200):
        one.learn(sensors[t], actions[t : t + 1], probs[t : t + 1])
    batch.learn(sensors[1:], actions[1:], probs[1:])
    assert_same(one.horde_state(), batch.horde_state(), atol=1e-9)  # GTD owes within a batch: same to rounding


def stream_spec(actions: int = 3) -> RunSpec:
    return RunSpec.model_validate(
        {
            "world": {"kind": "stream", "actions": actions,
                      "sensors": [{"name": "a", "low": 0, "high": 1}, {"name": "b", "low": -1, "high": 1}]},
            "features": {"kind": "sensors", "tilings": 2, "tiles": 2, "size": 16,
                         "sensors": [{"sensor": "a", "low": 0, "high": 1}]},
            "demons": [
                {"name": "a_next", "learner": "gq", "policy": {"kind": "fixed", "probabilities": [0.5, 0.25, 0.25]},
                 "cumulant": {"sensor": "a"}, "discount": 0},
                {"name": "b_soon", "learner": "td", "policy": "uniform", "cumulant": {"sensor": "b"}, "discount": 0.5},
            ],
        }
    )  # fmt: skip


def test_three_actions_learn_a_one_step_question_by_hand() -> None:
    """One state (a = 1 always): GQ over three actions, gamma 0, alpha 1 per active feature count.

    With gamma = 0 the GQ update is theta += alpha (r - theta . phi) phi; phi(s, a) has k = 2 + 1 active
    features, so after one update on action 1 with r = 1 and alpha = 0.03 / 3 per feature, q(s, 1) =
    3 * 0.01 * 1 = 0.03, q(s, 0) = q(s, 2) = 0, and the prediction is pi . q = 0.25 * 0.03 = 0.0075.
    """
    spec = stream_spec()
    loop = Learner(Horde(spec))
    assert loop.num_actions == 3
    loop.observe(np.array([1.0, 0.0]))
    loop.learn(np.array([1.0, 0.0]), [1], [1 / 3])
    q = loop.q()[spec.demons.index(next(d for d in spec.demons if d.name == "a_next"))]
    np.testing.assert_allclose(q, [0.0, 0.03, 0.0], atol=1e-15)
    assert loop.prediction()[0] == pytest.approx(0.25 * 0.03)


def test_bad_rows_name_the_field_and_learn_nothing() -> None:
    loop = Learner(Horde(stream_spec()))
    loop.observe(np.array([0.5, 0.0]))
    before = loop.horde_state()
    with pytest.raises(ExternalRecordError, match=r"^sensors: 3 readings, the world has 2"):
        loop.learn(np.array([[0.5, 0.0, 1.0]]), [0], [0.5])
    with pytest.raises(ExternalRecordError, match=r"^sensors\.b: nan"):
        loop.learn(np.array([[0.5, np.nan]]), [0], [0.5])
    with pytest.raises(ExternalRecordError, match=r"^action: 3 is not one of the world's 3 actions"):
        loop.learn(np.array([[0.5, 0.0]]), [3], [0.5])
    with pytest.raises(ExternalRecordError, match=r"^behaviour_probabilities"):
        loop.learn(np.array([[0.5, 0.0]]), [0], [0.0])
    assert_same(before, loop.horde_state())
    loop.learn(np.array([[0.5, 0.0]]), [2], [1 / 3])
    assert loop.steps == 1
