"""Every learner of the registry equals the plain oracle, with binary and with real-valued features.

Real-valued features: a table whose rows carry values (an index listed twice adds up), polynomial and Fourier
bases over the position, radial basis functions, and the sensors themselves as linear features. The demons
cover every declared learner and step-size mode (`horde.spec.learners`: a learner added later is covered
here without a word), over given and followed target policies and a control demon's own, continuations
that depend on the state, a conditioned block and a demon reset at every episode start; the engine's own
transitions (`Simulation`, the trace cut at 0) are replayed into `reference.ReferenceHorde` and compared at
every step to 1e-9 (test_engine_online.replay).
"""

from __future__ import annotations

from itertools import cycle
from typing import Any

import numpy as np
import pytest

from grids import CRIT, GOAL, PIT, WALL, grid
from horde.core.features import StateCoder
from horde.core.reference import state_features
from horde.spec import FeatureSpec, RunSpec, learner_info, learner_names

from .test_engine_online import replay

XY = [{"sensor": "x"}, {"sensor": "y"}]  # ranges left out: the world's [0, 500)
REAL: list[dict[str, Any]] = [
    {"kind": "table", "sensor": "in:crit", "table": [[0, 1, 1], [2, 1, 0]], "values": [[0.5, -1.0, 0.25],
                                                                                      [2.0, 0.75, -0.5]]},
    {"kind": "fourier", "sensors": XY, "order": 2},
    {"kind": "polynomial", "sensors": XY, "order": 2},
    {"kind": "rbf", "sensors": XY, "centres": 3},
    {"kind": "linear", "sensors": [*XY, {"sensor": "steps", "low": 0, "high": 40}]},
]  # fmt: skip
BINARY: list[dict[str, Any]] = [
    {"kind": "stripes", "parts": 5},
    {"kind": "tiles", "tilings": 3, "tiles": 3},
    {"kind": "grid", "tiles": 5},
    {"kind": "sensors", "tilings": 2, "tiles": 3, "size": 20, "sensors": XY},
]
FIXED = {"kind": "fixed", "probabilities": [0.4, 0.1, 0.2, 0.3]}
POLICIES: list[Any] = ["uniform", FIXED, {"of": "base"}]
CONTINUATIONS: list[Any] = [0.9, {"if": {"sensor": "in:crit"}, "then": 0, "else": 0.95}]


def demons(features: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """A softmax control demon, then one demon per declared learner and step-size mode, the feature kinds,
    policies and continuations taken in turn; a conditioned copy and a reset-each-episode one of the first."""
    kinds, policies, continuations = cycle(features), cycle(POLICIES), cycle(CONTINUATIONS)
    out: list[dict[str, Any]] = [{"name": "base", "policy": {"kind": "softmax", "temperature": 0.5},
                                  "cumulant": {"sensor": "reward"}, "features": features[1], "alpha": 0.2}]  # fmt: skip
    for name in learner_names():
        for mode in learner_info(name).step_sizes:
            policy = next(policies)
            out.append({"name": f"{name}_{mode}", "learner": name, "step_size": mode, "policy": policy,
                        "features": next(kinds), "cumulant": {"sensor": "bump"}, "continuation": next(continuations),
                        "lambda": 0.7 if learner_info(name).traces else 0.0})  # fmt: skip
    first = out[1]
    condition = {"demon": "base", "thresholds": [0.0]}
    out.append({**first, "name": "conditioned", "features": {**features[0], "condition": condition}})
    out.append({**first, "name": "forgets", "reset": "episode", "policy": "uniform"})
    return out


def spec(features: list[dict[str, Any]]) -> RunSpec:
    return RunSpec.model_validate({
        "world": grid(GOAL, PIT, WALL, CRIT, slip=0.1, max_steps=40),
        "learning": {"lambda": 0.9, "alpha": 0.1, "alpha_w": 0.01, "meta_step": 0.02, "autostep_tau": 100},
        "behaviour": {"kind": "epsilon_greedy", "demon": "base", "epsilon": 0.5},
        "demons": demons(features),
        "seed": 3,
    })  # fmt: skip


@pytest.mark.slow
@pytest.mark.parametrize("features", [REAL, BINARY], ids=["real-valued features", "binary features"])
def test_every_learner_equals_the_oracle(features: list[dict[str, Any]]) -> None:
    run = spec(features)
    sim, _, episodes = replay(run, 0.0, 400)
    assert episodes >= 5
    modes = {(d.learner, d.step_size or "constant") for d in run.demons if d.name != "base"}
    assert modes == {(n, m) for n in learner_names() for m in learner_info(n).step_sizes}, "every learner ran"
    assert all(spec.binary for spec in (FeatureSpec.model_validate(f) for f in features)) == (features is BINARY)
    state = sim.horde_state
    learned = [name for name in sim.horde.names if np.abs(sim.horde.weights(state, name)).max() > 1e-3]
    assert len(learned) == len(sim.horde.names), set(sim.horde.names) - set(learned)
    assert not state.diverged.any()


@pytest.mark.parametrize("features", REAL, ids=[f["kind"] for f in REAL])
def test_the_compiled_coder_equals_the_plain_one(features: dict[str, Any]) -> None:
    """At random states of the grid world: the engine's coder (`features.code`, as `StateCoder.dense`) gives
    the oracle's dense vector (`reference.state_features`)."""
    run = spec(REAL)
    fspec = FeatureSpec.model_validate(features)
    names, bounds = run.world.sensor_names(), run.world.sensor_bounds()
    coder = StateCoder(fspec, 500.0, 500.0, names, bounds)
    rng = np.random.default_rng(0)
    sensors = np.zeros((50, len(names)))
    sensors[:, 0], sensors[:, 1] = rng.uniform(0, 500, 50), rng.uniform(0, 500, 50)
    sensors[:, names.index("steps")] = rng.integers(0, 41, 50)
    sensors[:, names.index("in:crit")] = rng.integers(0, 2, 50)
    dense = coder.dense(sensors[:, 0], sensors[:, 1], sensors=sensors)
    for row, values in zip(sensors, dense, strict=True):
        plain = state_features(fspec, row[0], row[1], 500.0, 500.0, 0.0, dict(zip(names, row.tolist(), strict=True)),
                               bounds)  # fmt: skip
        np.testing.assert_allclose(values, plain, rtol=0, atol=1e-12)
    assert np.abs(dense).max() > 0.1 and len(np.unique(dense.round(6), axis=0)) >= 2, "the states differ"
