"""The oracle over any number of actions: the engine's external path equals the plain ReferenceHorde on a
stream world with three actions (as Acrobot has), for every kind of target policy over those actions."""

from __future__ import annotations

import numpy as np
import pytest

from horde.core.horde import Horde
from horde.core.learner import Learner
from horde.core.reference import ReferenceHorde
from horde.spec import RunSpec

TOLERANCE = 1e-9
FIXED = {"kind": "fixed", "probabilities": [0.1, 0.1, 0.8]}
SIGN = {"kind": "sign", "sensor": "b", "actions": [0, 2], "epsilon": 0.2}


def three_action_spec() -> RunSpec:
    return RunSpec.model_validate({
        "name": "three",
        "world": {"kind": "stream", "actions": 3,
                  "sensors": [{"name": "a", "low": 0, "high": 1}, {"name": "b", "low": -1, "high": 1}]},
        "features": {"kind": "sensors", "tilings": 3, "tiles": 4, "size": 128,
                     "sensors": [{"sensor": "a", "low": 0, "high": 1}, {"sensor": "b", "low": -1, "high": 1}]},
        "learning": {"lambda": 0.8, "alpha": 0.1, "alpha_w": 0.01},
        "demons": [
            {"name": "gq_fixed", "learner": "gq", "policy": FIXED, "cumulant": {"sensor": "a"}, "discount": 0.9},
            {"name": "gtd_sign", "learner": "gtd", "policy": SIGN, "cumulant": {"sensor": "b"}, "discount": 0.8},
            {"name": "td_uniform", "learner": "td", "policy": "uniform", "cumulant": 1,
             "continuation": {"if": {"max": [{"sensor": "a"}, -1]}, "then": 0.95, "else": 0.5}},
            {"name": "control", "learner": "gq", "policy": {"kind": "epsilon_greedy", "epsilon": 0.1},
             "cumulant": {"sensor": "b"}, "discount": 0.7},
            {"name": "follows", "learner": "gtd", "policy": {"of": "control"}, "cumulant": {"prediction": "gq_fixed"},
             "discount": 0.5},
        ],
    })  # fmt: skip


@pytest.mark.parametrize("seed", [0, 1])
def test_the_engine_equals_the_reference_on_a_three_action_stream(seed: int) -> None:
    spec = three_action_spec()
    assert spec.world.num_actions() == 3
    loop = Learner(Horde(spec, cut=0.0))  # no trace cut: the exact equations
    ref = ReferenceHorde(spec)
    rng = np.random.default_rng(seed)
    names = spec.world.sensor_names()

    def sensors() -> np.ndarray:
        return np.array([rng.random(), rng.uniform(-1, 1)])  # [S]

    def compare(step: int) -> None:
        engine = loop.prediction()  # [D] demon order
        for i, name in enumerate(loop.horde.names):
            assert engine[i] == pytest.approx(ref.demons[name].prediction, abs=TOLERANCE), (step, name)

    first = sensors()
    loop.observe(first)
    ref.observe(0.0, 0.0, dict(zip(names, first.tolist(), strict=True)))
    compare(0)
    actions_seen = set()
    for step in range(1, 601):
        b = rng.dirichlet(np.ones(3))  # [3] a behaviour that changes every step; b(a_t | s_t) is exact
        action = int(rng.choice(3, p=b))
        actions_seen.add(action)
        nxt = sensors()
        ends = step % 150 == 0  # episodes end now and then (terminated): traces restart after
        loop.learn(nxt[None], [action], [b[action]], terminated=ends)
        ref.learn(action, float(b[action]), 0.0, 0.0, dict(zip(names, nxt.tolist(), strict=True)), ends)
        compare(step)
        if ends:
            start = sensors()
            loop.observe(start)
            ref.observe(0.0, 0.0, dict(zip(names, start.tolist(), strict=True)))
            compare(step)
    assert actions_seen == {0, 1, 2}
    weights = {name: np.abs(ref.demons[name].theta).max() for name in ref.demons}
    assert min(weights.values()) > 1e-3, weights  # every demon learned something
    assert ref.demons["gq_fixed"].theta.shape == (3 * 129,), "GQ holds one block of state features per action"
