"""What the learners owe is settled wherever something outside the compiled loop reads the weights.

TD, emphatic TD and true online TD defer each update by one step (`learners.td_pass`), GTD and the learners
sharing its kernel (TDRC, GTD2, the original GTD) theirs (`learners.gtd_pass`), GQ its correction at x_{t+1}
(`learners.gradient`): theta and w owe between the steps of a call. Each test below reads the weights at one
such place after many steps in one call (so with something owed), against the plain reference fed the same
transitions one step at a time, for a Horde of TD demons, one of the GTD family, one of GQ, one of emphatic TD
and one of true online TD (`family`); each fails when the settling that guards its place is taken out (checked:
the end of a call, `loop.run`; an episode's start, `step.observe`; a freeze, `step.freeze_diverged`, in
tests/core/test_fast.py), and each family's when its learner's settle is.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from tests.core.test_fast import assert_same

from horde.core.learners import GQ_CODE
from horde.core.policies import FIXED
from horde.core.reference import ReferenceHorde
from horde.core.simulation import Simulation
from horde.runs import snapshot
from horde.spec import RunSpec

TOLERANCE = 1e-9
TARGET = {"kind": "fixed", "probabilities": [0.7, 0.1, 0.1, 0.1]}
FAMILIES: dict[str, list[dict[str, Any]]] = {
    "td": [
        {"name": "bump", "learner": "td", "policy": "uniform", "cumulant": {"sensor": "bump"}, "discount": 0.9},
        {"name": "x", "learner": "td", "policy": "uniform", "cumulant": {"sensor": "x"}, "discount": 0.5},
        {"name": "bump2", "learner": "td", "policy": "uniform", "cumulant": {"sensor": "bump"}, "discount": 0.9,
         "reset": "episode"},
        {"name": "y", "learner": "gtd", "policy": TARGET, "cumulant": {"sensor": "y"}, "discount": 0.8},
    ],
    "gtd": [  # every form of GTD's one pass: TDC (two classes), TDRC (h kept scaled), GTD2, the original GTD
        {"name": "bump", "learner": "gtd", "policy": TARGET, "cumulant": {"sensor": "bump"}, "discount": 0.9},
        {"name": "x", "learner": "tdrc", "policy": "uniform", "cumulant": {"sensor": "x"}, "discount": 0.5},
        {"name": "bump2", "learner": "gtd", "policy": "uniform", "cumulant": {"sensor": "bump"}, "discount": 0.9,
         "reset": "episode"},
        {"name": "y", "learner": "gtd2", "policy": TARGET, "cumulant": {"sensor": "y"}, "discount": 0.8},
        {"name": "y1", "learner": "gtd1", "policy": TARGET, "cumulant": {"sensor": "y"}, "discount": 0.8},
    ],
    "etd": [  # emphatic TD on TD's kernel: the followon and emphasis in the trace, two classes, one forgetting
        {"name": "bump", "learner": "etd", "policy": TARGET, "cumulant": {"sensor": "bump"}, "discount": 0.9},
        {"name": "x", "learner": "etd", "policy": "uniform", "cumulant": {"sensor": "x"}, "discount": 0.5},
        {"name": "bump2", "learner": "etd", "policy": TARGET, "cumulant": {"sensor": "bump"}, "discount": 0.9,
         "reset": "episode"},
    ],
    "gq": [  # action values: a fixed target (one class), greedy (a block of one), two softmax demons in one block
        # (a trace class each, decayed in the support pass), one of them forgetting
        {"name": "bump", "learner": "gq", "policy": TARGET, "cumulant": {"sensor": "bump"}, "discount": 0.9},
        {"name": "x", "learner": "gq", "policy": "greedy", "cumulant": {"sensor": "x"}, "discount": 0.5},
        {"name": "bump2", "learner": "gq", "policy": {"kind": "softmax", "temperature": 0.5},
         "cumulant": {"sensor": "bump"}, "discount": 0.9, "reset": "episode"},
        {"name": "y2", "learner": "gq", "policy": {"kind": "softmax", "temperature": 2.0},
         "cumulant": {"sensor": "y"}, "discount": 0.8},
    ],
    "true_online_td": [  # the walk pays along x_{t-1} too; two classes (alpha 0.2 and 0.1: a dutch trace holds it)
        {"name": "bump", "learner": "true_online_td", "policy": TARGET, "cumulant": {"sensor": "bump"},
         "discount": 0.9},
        {"name": "x", "learner": "true_online_td", "policy": "uniform", "cumulant": {"sensor": "x"}, "discount": 0.5,
         "alpha": 0.1},
        {"name": "bump2", "learner": "true_online_td", "policy": TARGET, "cumulant": {"sensor": "bump"},
         "discount": 0.9, "reset": "episode"},
    ],
}  # fmt: skip


@pytest.fixture(params=sorted(FAMILIES))
def family(request: pytest.FixtureRequest) -> str:
    return str(request.param)


def spec(max_steps: int, family: str) -> RunSpec:
    return RunSpec.model_validate(
        {
            "world": {"width": 500, "height": 500, "step": 50, "start": [0, 0], "max_steps": max_steps},
            "features": {"kind": "tiles", "tilings": 4, "tiles": 4},
            "learning": {"lambda": 0.9, "alpha": 0.2, "alpha_w": 0.05},
            "behaviour": "uniform",
            "demons": FAMILIES[family],
            "seed": 7,
        }
    )


def learned(max_steps: int, steps: int, family: str) -> tuple[Simulation, ReferenceHorde]:
    """`steps` steps in one call, and the reference fed the same transitions (a twin stepped one at a time: the
    behaviour is uniform, so the trajectory does not depend on the weights)."""
    run_spec = spec(max_steps, family)
    sim, twin = Simulation(run_spec, cut=0.0), Simulation(run_spec, cut=0.0)
    ref = ReferenceHorde(run_spec)
    names = twin.world.sensor_names
    ref.observe(*twin.position, dict(zip(names, twin.start_sensors.tolist(), strict=True)))
    for _ in range(steps):
        result = twin.step()
        sensors = twin.sensors
        ref.learn(result.action, twin.behaviour_probability, float(sensors[0]), float(sensors[1]),
                  dict(zip(names, sensors.tolist(), strict=True)), result.terminated)  # fmt: skip
        if result.done:
            ref.observe(*twin.position, dict(zip(names, twin.start_sensors.tolist(), strict=True)))
    sim.run(steps)
    assert sim.position == twin.position and sim.episode == twin.episode
    return sim, ref


def assert_weights(sim: Simulation, ref: ReferenceHorde) -> None:
    """theta and w of every demon (w: the secondary weights, 0 for TD), and its prediction."""
    state = sim.horde_state
    for i, name in enumerate(sim.horde.names):
        theta, w, _ = sim.horde.demon_arrays(state, name)
        np.testing.assert_allclose(theta, ref.demons[name].theta, rtol=0, atol=TOLERANCE, err_msg=name)
        np.testing.assert_allclose(w, ref.demons[name].w, rtol=0, atol=TOLERANCE, err_msg=f"{name}'s w")
        assert state.prediction[i] == pytest.approx(ref.demons[name].prediction, abs=TOLERANCE), name
        assert np.abs(ref.demons[name].theta).max() > 1e-2, f"{name} learned"
        learner = ref.demons[name].spec.learner
        has_w = learner not in ("td", "etd", "true_online_td")
        assert not has_w or np.abs(ref.demons[name].w).max() > 1e-3, f"{name} learned a w"


def test_gqs_family_holds_a_block_of_several_demons_over_their_own_values() -> None:
    """(`bump2` and `y2`: a block of two trace classes, each demon's own, the form whose traces decay in GQ's support
    pass, `gradient._classes_pass`; the other two are blocks of one demon.)"""
    lay = Simulation(spec(10_000, "gq")).learner.engine.t.lay
    own = [b for b in range(lay.learner.shape[0]) if lay.learner[b] == GQ_CODE and lay.policy[b] != FIXED]
    assert sorted(int(lay.ncls[b]) for b in own) == [1, 2]


def test_a_call_ends_owing_nothing(family: str) -> None:
    sim, ref = learned(10_000, 157, family)
    assert sim.episode == 0
    assert_weights(sim, ref)


def test_an_episode_start_pays_what_is_owed_before_it_clears_the_traces(family: str) -> None:
    """Episodes of 15 steps, one demon forgetting its weights at each: the last step's update is paid before the
    traces go to zero (and before `bump2` forgets)."""
    sim, ref = learned(15, 157, family)
    assert sim.episode >= 8
    assert_weights(sim, ref)


def test_a_snapshot_holds_whole_weights(family: str) -> None:
    sim, ref = learned(10_000, 157, family)
    frozen = snapshot.capture(sim, sim.spec, "paused", None, None)
    restored = snapshot.restore(snapshot.from_bytes(snapshot.to_bytes(frozen))).sim
    assert isinstance(restored, Simulation)
    assert_weights(restored, ref)


def test_a_value_map_reads_whole_weights(family: str) -> None:
    sim, ref = learned(10_000, 157, family)
    for x, y in ((25.0, 25.0), (260.0, 140.0), (480.0, 470.0)):
        ours = sim.predictions_at(x, y)
        ref.observe(x, y)  # (clears the reference's traces: its weights are what is compared)
        for name, demon in ref.demons.items():
            if demon.spec.reset == "episode":  # (the reference's observe made it forget)
                continue
            assert ours[name] == pytest.approx(demon.prediction, abs=TOLERANCE), (name, x, y)


def test_a_demon_joining_keeps_the_others_whole_weights(family: str) -> None:
    sim, ref = learned(10_000, 157, family)
    data = sim.spec.model_dump(by_alias=True)
    data["demons"].append({"name": "late", "learner": family, "policy": "uniform", "cumulant": {"sensor": "x"},
                           "discount": 0.9})  # fmt: skip
    joined = sim.with_spec(RunSpec.model_validate(data))
    state = joined.horde_state
    for name in sim.horde.names:
        if ref.demons[name].spec.reset == "episode":  # (forgets at the joining, which starts traces afresh)
            continue
        theta, w, _ = joined.horde.demon_arrays(state, name)
        np.testing.assert_allclose(theta, ref.demons[name].theta, rtol=0, atol=TOLERANCE, err_msg=name)
        np.testing.assert_allclose(w, ref.demons[name].w, rtol=0, atol=TOLERANCE, err_msg=f"{name}'s w")


def test_true_online_td_pays_the_rows_of_x_t_that_the_cut_leaves_without_a_trace() -> None:
    """True online TD owes fix_t x_t as well as coef_t e_t; where the cut leaves a row of x_t without a trace, the
    next walk does not reach it, so `td_pass.finish` pays it at once. A cut of 0.05 drops the fresh rows of
    steps with rho_t below 1 (what x_t adds there is about 0.02) and keeps the rows seen lately: after every call
    the demons' predictions are their weights times the features, as the algebra of the values assumes."""
    data = spec(10_000, "true_online_td").model_dump(by_alias=True)
    sim = Simulation(RunSpec.model_validate(data), cut=0.05)
    for _ in range(300):
        sim.step()
        state = sim.horde_state
        for i, name in enumerate(sim.horde.names):
            theta = sim.horde.weights(state, name)
            assert state.prediction[i] == pytest.approx(theta[state.features[0]].sum(), abs=1e-12), name
    assert np.abs(sim.horde.weights(sim.horde_state, "bump")).max() > 1e-2, "it learned"


def test_the_length_of_a_call_changes_no_bit(family: str) -> None:
    """157 steps in one call and in 157 calls of one step (each settled at its end) give the same weights, traces
    and predictions to the last bit: a settle pays with the walk's operations in the walk's order."""
    run_spec = spec(10_000, family)
    bulk, single = Simulation(run_spec, cut=0.0), Simulation(run_spec, cut=0.0)
    bulk.run(157)
    for _ in range(157):
        single.step()
    assert_same(bulk.horde_state, single.horde_state)
