"""`[learning] dtype = "float32"`: weights, secondary weights, traces and the per-weight vectors in float32, sums
in float64; learning stays where float64's does, to float32's tolerance."""

from __future__ import annotations

import numpy as np
import pytest
from benchmarks import workloads
from pydantic import ValidationError

from horde.core.reference import ReferenceHorde
from horde.core.simulation import Simulation
from horde.spec import RunSpec

from .test_engine_vs_reference import BEHAVIOURS, compare, run_spec

FLOAT32_TOLERANCE = 5e-5  # relative, over 300 steps: the largest gap measured was 1.5e-5


def with_dtype(spec: RunSpec, dtype: str) -> RunSpec:
    data = spec.model_dump(by_alias=True)
    data["learning"]["dtype"] = dtype
    return RunSpec.model_validate(data)


def test_float32_keeps_every_per_weight_array_in_float32_and_the_rest_in_float64() -> None:
    sim = Simulation(with_dtype(run_spec("uniform"), "float32"), cut=0.0)
    t = sim.learner.engine.t
    for name, array in (("theta", t.wts.theta), ("w", t.wts.w), ("trace", t.wts.trace), ("h", t.met.h),
                        ("u", t.met.u), ("step_a", t.onl.step_a), ("step_v", t.onl.step_v),
                        ("trace2", t.onl.trace2)):  # fmt: skip
        assert array.dtype == np.float32, name
    assert t.dem.pred.dtype == np.float64 and t.wts.owed.dtype == np.float64
    sim.run(50)
    state = sim.horde_state
    assert all(a.dtype == np.float32 for part in (state.theta, state.w, state.e) for a in part)
    assert state.prediction.dtype == np.float64


@pytest.mark.parametrize("case", list(BEHAVIOURS))
def test_float32_engine_equals_the_reference_to_float32s_tolerance(case: str) -> None:
    """Every learner (the reference spec mixes them all) in float32 against the float64 reference, step by step."""
    behaviour, world = BEHAVIOURS[case]
    spec = with_dtype(run_spec(behaviour, **world), "float32")
    sim = Simulation(spec, cut=0.0)
    ref = ReferenceHorde(spec)
    names = sim.world.sensor_names
    ref.observe(*sim.position, dict(zip(names, sim.start_sensors.tolist(), strict=True)))
    largest = 0.0
    for step in range(1, 301):
        result = sim.step()
        sensors = sim.sensors
        ref.learn(result.action, sim.behaviour_probability, float(sensors[0]), float(sensors[1]),
                  dict(zip(names, sensors.tolist(), strict=True)), result.terminated)  # fmt: skip
        if result.done:
            ref.observe(*sim.position, dict(zip(names, sim.start_sensors.tolist(), strict=True)))
        largest = max(largest, compare(sim, ref, step, FLOAT32_TOLERANCE, relative=True))
    print(f"largest relative gap {largest:.2e}")
    assert largest > 1e-9, "float32 rounds: the engine is not computing in float64 after all"


@pytest.mark.parametrize("learner", ["td", "gtd"])
def test_float32_nexting_predictions_stay_within_1e_5_of_float64_after_10000_steps(learner: str) -> None:
    """The nexting stream (57 sensors tiled into 6065 features, five timescales), TD and GTD (whose walk sums a few
    rows at a time in float32 before it adds them into float64: `gtd_pass.SUM_ROWS`): 10,000 steps."""
    spec = workloads.spec("nexting", 60, learner)
    predictions = {}
    for dtype in ("float64", "float32"):
        sim = Simulation(with_dtype(spec, dtype))
        sim.run(10_000)
        predictions[dtype] = sim.learner.engine.prediction()
    scale = float(np.abs(predictions["float64"]).max())
    assert scale > 1.0
    assert float(np.abs(predictions["float32"] - predictions["float64"]).max()) <= 1e-5 * scale


def test_a_dtype_other_than_float32_or_float64_is_refused_naming_the_field() -> None:
    data = run_spec("uniform").model_dump(by_alias=True)
    data["learning"]["dtype"] = "float16"
    with pytest.raises(ValidationError) as caught:
        RunSpec.model_validate(data)
    assert [e["loc"] for e in caught.value.errors()] == [("learning", "dtype")]
