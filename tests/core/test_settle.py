"""What the learners owe is settled wherever something outside the compiled loop reads the weights.

TD defers each update by one step and GTD / GQ their correction at x_{t+1} (`learners.td_pass`,
`learners.gradient`): theta owes between the steps of a call. Each test below reads the weights at one such
place after many steps in one call (so with something owed), against the plain reference fed the same
transitions one step at a time; each fails when the settling that guards its place is taken out (checked:
the end of a call, `loop.run`; an episode's start, `step.observe`; a freeze, `step.freeze_diverged`, in
tests/core/test_fast.py).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from horde.core.reference import ReferenceHorde
from horde.core.simulation import Simulation
from horde.runs import snapshot
from horde.spec import RunSpec

TOLERANCE = 1e-9
DEMONS: list[dict[str, Any]] = [
    {"name": "bump", "learner": "td", "policy": "uniform", "cumulant": {"sensor": "bump"}, "discount": 0.9},
    {"name": "x", "learner": "td", "policy": "uniform", "cumulant": {"sensor": "x"}, "discount": 0.5},
    {"name": "bump2", "learner": "td", "policy": "uniform", "cumulant": {"sensor": "bump"}, "discount": 0.9,
     "reset": "episode"},
    {"name": "y", "learner": "gtd", "policy": {"kind": "fixed", "probabilities": [0.7, 0.1, 0.1, 0.1]},
     "cumulant": {"sensor": "y"}, "discount": 0.8},
]  # fmt: skip


def spec(max_steps: int) -> RunSpec:
    return RunSpec.model_validate(
        {
            "world": {"width": 500, "height": 500, "step": 50, "start": [0, 0], "max_steps": max_steps},
            "features": {"kind": "tiles", "tilings": 4, "tiles": 4},
            "learning": {"lambda": 0.9, "alpha": 0.2, "alpha_w": 0.05},
            "behaviour": "uniform",
            "demons": DEMONS,
            "seed": 7,
        }
    )


def learned(max_steps: int, steps: int) -> tuple[Simulation, ReferenceHorde]:
    """`steps` steps in one call, and the reference fed the same transitions (a twin stepped one at a time: the
    behaviour is uniform, so the trajectory does not depend on the weights)."""
    run_spec = spec(max_steps)
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
    state = sim.horde_state
    for i, name in enumerate(sim.horde.names):
        np.testing.assert_allclose(sim.horde.weights(state, name), ref.demons[name].theta, rtol=0, atol=TOLERANCE,
                                   err_msg=name)  # fmt: skip
        assert state.prediction[i] == pytest.approx(ref.demons[name].prediction, abs=TOLERANCE), name
        assert np.abs(ref.demons[name].theta).max() > 1e-2, f"{name} learned"


def test_a_call_ends_owing_nothing() -> None:
    sim, ref = learned(10_000, 157)
    assert sim.episode == 0
    assert_weights(sim, ref)


def test_an_episode_start_pays_what_is_owed_before_it_clears_the_traces() -> None:
    """Episodes of 15 steps, one demon forgetting its weights at each: the last step's update is paid before the
    traces go to zero (and before `bump2` forgets)."""
    sim, ref = learned(15, 157)
    assert sim.episode >= 8
    assert_weights(sim, ref)


def test_a_snapshot_holds_whole_weights() -> None:
    sim, ref = learned(10_000, 157)
    frozen = snapshot.capture(sim, sim.spec, "paused", None, None)
    restored = snapshot.restore(snapshot.from_bytes(snapshot.to_bytes(frozen))).sim
    assert isinstance(restored, Simulation)
    assert_weights(restored, ref)


def test_a_value_map_reads_whole_weights() -> None:
    sim, ref = learned(10_000, 157)
    for x, y in ((25.0, 25.0), (260.0, 140.0), (480.0, 470.0)):
        ours = sim.predictions_at(x, y)
        ref.observe(x, y)  # (clears the reference's traces: its weights are what is compared)
        for name, demon in ref.demons.items():
            if demon.spec.reset == "episode":  # (the reference's observe made it forget)
                continue
            assert ours[name] == pytest.approx(demon.prediction, abs=TOLERANCE), (name, x, y)


def test_a_demon_joining_keeps_the_others_whole_weights() -> None:
    sim, ref = learned(10_000, 157)
    data = sim.spec.model_dump(by_alias=True)
    data["demons"].append({"name": "late", "learner": "td", "policy": "uniform", "cumulant": {"sensor": "x"},
                           "discount": 0.9})  # fmt: skip
    joined = sim.with_spec(RunSpec.model_validate(data))
    state = joined.horde_state
    for name in sim.horde.names:
        if ref.demons[name].spec.reset == "episode":  # (forgets at the joining, which starts traces afresh)
            continue
        np.testing.assert_allclose(joined.horde.weights(state, name), ref.demons[name].theta, rtol=0,
                                   atol=TOLERANCE, err_msg=name)  # fmt: skip
