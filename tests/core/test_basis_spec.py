"""Real-valued feature kinds in the spec: what they code to, and what is refused, naming the field.

Refused before anything is allocated (the spec does not validate, so no Horde is built): a feature value that
is not finite, a basis order or RBF count past its bound, a basis over a sensor without a range.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from pydantic import ValidationError

from horde.core.features import StateCoder
from horde.spec import FeatureSpec, RunSpec

STREAM = {"kind": "stream", "actions": 2, "sensors": [{"name": "a", "low": 0, "high": 4}, {"name": "b"}]}


def problem(features: dict[str, Any], world: dict[str, Any] | None = None) -> tuple[tuple[Any, ...], str]:
    with pytest.raises(ValidationError) as info:
        RunSpec.model_validate({"world": world or STREAM, "features": features})
    error = info.value.errors()[0]
    return tuple(error["loc"]), error["msg"]


@pytest.mark.parametrize(
    ("features", "loc", "words"),
    [
        ({"kind": "table", "sensor": "a", "table": [[0, 1]] * 5, "values": [[1.0, math.nan]] + [[1, 1]] * 4},
         ("features", "values", 0, 1), "finite number"),
        ({"kind": "table", "sensor": "a", "table": [[0, 1]] * 5, "values": [[1.0, math.inf]] + [[1, 1]] * 4},
         ("features", "values", 0, 1), "finite number"),
        ({"kind": "table", "sensor": "a", "table": [[0, 1]] * 5, "values": [[1.0]] * 5}, ("features", "values"),
         "the same shape"),
        ({"kind": "fourier", "sensors": [{"sensor": "a"}], "order": 33}, ("features", "order"), "less than or equal"),
        ({"kind": "polynomial", "sensors": [{"sensor": "a"}] * 4, "order": 10}, ("features", "order"),
         "14641 features, more than 10000"),
        ({"kind": "rbf", "sensors": [{"sensor": "a"}], "centres": 65}, ("features", "centres"), "less than or equal"),
        ({"kind": "rbf", "sensors": [{"sensor": "a"}] * 3, "centres": 22}, ("features", "centres"),
         "10648 features, more than 10000"),
        ({"kind": "rbf", "sensors": [{"sensor": "a"}], "centres": 3, "width": 0}, ("features", "width"),
         "greater than 0"),
        ({"kind": "fourier", "sensors": [{"sensor": "b"}], "order": 2}, ("features", "sensors", 0, "low"),
         "sensor 'b' has no low bound in this world"),
        ({"kind": "linear", "sensors": [{"sensor": "b", "low": -1}]}, ("features", "sensors", 0, "high"),
         "no high bound"),
        ({"kind": "linear", "sensors": [{"sensor": "c", "low": 0, "high": 1}]}, (), "reads unknown sensor 'c'"),
        ({"kind": "fourier", "sensors": [{"sensor": "a"}]}, ("features",), "need an order"),
        ({"kind": "linear", "sensors": [{"sensor": "a"}], "order": 2}, ("features",), "order belongs to them only"),
        ({"kind": "rbf", "sensors": [{"sensor": "a"}]}, ("features",), "rbf features need centres"),
    ],
)  # fmt: skip
def test_bad_bases_and_values_are_refused_naming_the_field(features: dict[str, Any], loc: tuple[Any, ...],
                                                           words: str) -> None:  # fmt: skip
    where, message = problem(features)
    assert where == loc and words in message, (where, message)


def test_a_basis_over_a_grid_sensor_takes_the_worlds_range() -> None:
    """x in [0, 500) on the default grid: x = 250 is u = 0.5, so the Fourier features of order 2 are
    cos(0), cos(pi / 2), cos(pi) = (1, 0, -1); the linear kind gives (0.5, 1)."""
    spec = RunSpec.model_validate({"features": {"kind": "fourier", "sensors": [{"sensor": "x"}], "order": 2}})
    names, bounds = spec.world.sensor_names(), spec.world.sensor_bounds()
    sensors = np.zeros((1, len(names)))
    sensors[0, 0] = 250.0
    coder = StateCoder(spec.features, 500, 500, names, bounds)
    np.testing.assert_allclose(coder.dense(np.zeros(1), np.zeros(1), sensors=sensors)[0], [1, 0, -1], atol=1e-15)
    linear = StateCoder(FeatureSpec.model_validate({"kind": "linear", "sensors": [{"sensor": "x"}]}), 500, 500,
                        names, bounds)  # fmt: skip
    np.testing.assert_allclose(linear.dense(np.zeros(1), np.zeros(1), sensors=sensors)[0], [0.5, 1.0])
    assert coder.k == 3 and not coder.binary


def test_polynomial_and_rbf_by_hand() -> None:
    """Two inputs scaled to (0.5, 1): polynomial order 1 over (c_a, c_b) in (0,0), (0,1), (1,0), (1,1) gives
    1, 1, 0.5, 0.5; an rbf of 2 centres per input (0 and 1, width 1) at (0.5, 1) gives exp(-(d^2)/2) for
    d^2 = 1.25, 0.25, 1.25, 0.25."""
    world = {"kind": "stream", "actions": 2, "sensors": [{"name": "a", "low": 0, "high": 4},
                                                         {"name": "b", "low": -1, "high": 1}]}  # fmt: skip
    inputs = [{"sensor": "a"}, {"sensor": "b"}]
    sensors = np.array([[2.0, 1.0]])
    for features, expected in (
        ({"kind": "polynomial", "sensors": inputs, "order": 1}, [1.0, 1.0, 0.5, 0.5]),
        ({"kind": "rbf", "sensors": inputs, "centres": 2}, np.exp(-np.array([1.25, 0.25, 1.25, 0.25]) / 2)),
    ):
        spec = RunSpec.model_validate({"world": world, "features": features})
        coder = StateCoder(spec.features, 1, 1, spec.world.sensor_names(), spec.world.sensor_bounds())
        np.testing.assert_allclose(coder.dense(np.zeros(1), np.zeros(1), sensors=sensors)[0], expected, rtol=1e-14)


def test_readings_past_a_range_are_clipped_to_it() -> None:
    spec = RunSpec.model_validate({"world": STREAM, "features": {"kind": "linear", "sensors": [{"sensor": "a"}]}})
    coder = StateCoder(spec.features, 1, 1, spec.world.sensor_names(), spec.world.sensor_bounds())
    dense = coder.dense(np.zeros(3), np.zeros(3), sensors=np.array([[-3.0, 0], [2.0, 0], [9.0, 0]]))
    np.testing.assert_allclose(dense[:, 0], [0.0, 0.5, 1.0])
