"""Compiled question programs (DESIGN section 4) equal the plain recursive interpreter."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from horde.core import reference
from horde.core.questions import Program
from horde.spec import AddExpr, IfExpr, MaxExpr, MinExpr, MulExpr, PredictionExpr, SensorExpr

SENSORS = ["x", "y", "bump", "in:goal", "in:crit", "reward"]
DEMONS = ["a", "b", "c"]
SENSOR_INDEX = {name: i for i, name in enumerate(SENSORS)}
# predictions are read by column: give the demons columns in an order other than their names'
DEMON_INDEX = {"a": 2, "b": 0, "c": 1}

# Halves in [-2, 2]: every sum, product, min and max of up to 24 of them is exact in float64, so the
# result cannot depend on the order of the operations. That matters for `if`: a condition that cancels
# to 0 in one order can be 1e-76 in another (numpy's reduceat does not add left to right). Arbitrary
# floats are checked below on expressions without `if`, where rounding stays within a tolerance.
halves = st.integers(-4, 4).map(lambda k: k / 2)
floats = st.floats(-10, 10, allow_nan=False)


def expressions(numbers, with_if: bool):
    leaves = st.one_of(
        numbers,
        st.sampled_from(SENSORS).map(lambda s: SensorExpr(sensor=s)),
        st.sampled_from(DEMONS).map(lambda d: PredictionExpr(prediction=d)),
    )

    def branches(children):
        items = st.lists(children, min_size=1, max_size=4)
        kinds = [
            items.map(lambda xs: AddExpr(add=xs)),
            items.map(lambda xs: MulExpr(mul=xs)),
            items.map(lambda xs: MinExpr(min=xs)),
            items.map(lambda xs: MaxExpr(max=xs)),
        ]
        if with_if:
            kinds.append(
                st.tuples(children, children, children).map(
                    lambda t: IfExpr.model_validate({"if": t[0], "then": t[1], "else": t[2]})
                )
            )
        return st.one_of(*kinds)

    return st.lists(st.recursive(leaves, branches, max_leaves=24), min_size=1, max_size=5)


def inputs(numbers, width: int, batch: int = 4):
    return st.lists(numbers, min_size=width * batch, max_size=width * batch).map(
        lambda v: np.array(v, dtype=float).reshape(batch, width)
    )


def cases(numbers, with_if: bool):
    """(expressions, sensors, predictions) drawn from `numbers`."""
    return st.tuples(expressions(numbers, with_if), inputs(numbers, len(SENSORS)), inputs(numbers, len(DEMONS)))


def check(exprs, sensors: np.ndarray, predictions: np.ndarray, tolerance: float) -> None:
    program = Program(exprs, SENSOR_INDEX, DEMON_INDEX)
    out = program.evaluate(sensors, predictions)
    assert out.shape == (len(sensors), len(exprs))
    for b in range(len(sensors)):
        s = {name: sensors[b, i] for name, i in SENSOR_INDEX.items()}
        p = {name: predictions[b, i] for name, i in DEMON_INDEX.items()}
        expected = [reference.evaluate_expr(e, s, p) for e in exprs]
        np.testing.assert_allclose(out[b], expected, rtol=tolerance, atol=tolerance)


@settings(max_examples=200, deadline=None)
@given(cases(halves, with_if=True))
def test_program_equals_the_recursive_interpreter(case):
    check(*case, tolerance=0.0)


@settings(max_examples=100, deadline=None)
@given(cases(floats, with_if=False))
def test_program_equals_the_recursive_interpreter_on_any_floats(case):
    check(*case, tolerance=1e-9)


def test_each_operator_by_hand():
    x = SensorExpr(sensor="x")
    y = SensorExpr(sensor="y")
    program = Program(
        [
            AddExpr(add=[x, y, 1.0]),
            MulExpr(mul=[x, y, 2.0]),
            MinExpr(min=[x, y, 0.0]),
            MaxExpr(max=[x, y]),
            IfExpr.model_validate({"if": SensorExpr(sensor="bump"), "then": 7.0, "else": x}),
            3.5,
            PredictionExpr(prediction="a"),
        ],
        SENSOR_INDEX,
        DEMON_INDEX,
    )
    sensors = np.zeros((3, len(SENSORS)))
    sensors[:, 0] = [2.0, -1.0, 4.0]  # x
    sensors[:, 1] = [3.0, 5.0, -2.0]  # y
    sensors[:, 2] = [0.0, 1.0, -0.5]  # bump: any value other than 0 is true
    predictions = np.array([[9.0, 9.0, 10.0], [9.0, 9.0, 20.0], [9.0, 9.0, 30.0]])  # a is column 2
    out = program.evaluate(sensors, predictions)
    assert out.tolist() == [
        [6.0, 12.0, 0.0, 3.0, 2.0, 3.5, 10.0],
        [5.0, -10.0, -1.0, 5.0, 7.0, 3.5, 20.0],
        [3.0, -16.0, -2.0, 4.0, 7.0, 3.5, 30.0],
    ]


def test_shared_subexpressions_are_stored_once_and_read_by_every_user():
    x = SensorExpr(sensor="x")
    shared = AddExpr(add=[x, 1.0])
    first = shared
    second = MulExpr(mul=[AddExpr(add=[SensorExpr(sensor="x"), 1.0]), 2.0])  # equal, not the same object
    third = IfExpr.model_validate({"if": AddExpr(add=[x, 1.0]), "then": AddExpr(add=[x, 1.0]), "else": 2.0})
    program = Program([first, second, third, 1.0], SENSOR_INDEX, DEMON_INDEX)
    # nodes: x, 1, add(x, 1), 2, mul(add, 2), if(add, add, 2) -- six, though the expressions hold 13
    assert program.num_nodes == 6
    sensors = np.zeros((2, len(SENSORS)))
    sensors[:, 0] = [3.0, -1.0]
    assert program.evaluate(sensors).tolist() == [[4.0, 8.0, 4.0, 1.0], [0.0, 0.0, 2.0, 1.0]]


def test_predictions_are_read_from_their_columns_and_required():
    program = Program([PredictionExpr(prediction="b"), PredictionExpr(prediction="c")], SENSOR_INDEX, DEMON_INDEX)
    assert program.reads_predictions
    sensors = np.zeros((1, len(SENSORS)))
    assert program.evaluate(sensors, np.array([[1.0, 2.0, 3.0]])).tolist() == [[1.0, 2.0]]
    with pytest.raises(ValueError, match="predictions"):
        program.evaluate(sensors)
    without = Program([SensorExpr(sensor="y")], SENSOR_INDEX, DEMON_INDEX)
    assert not without.reads_predictions
    assert without.evaluate(np.arange(6.0)[None]).tolist() == [[1.0]]


def test_deep_nesting_evaluates_in_height_order():
    # 1 + x, then * 0.5, alternately, 30 deep: the levels must run bottom-up
    expr: object = SensorExpr(sensor="x")
    plain = 0.5
    for level in range(30):
        if level % 2:
            expr, plain = MulExpr(mul=[expr, 0.5]), plain * 0.5
        else:
            expr, plain = AddExpr(add=[1.0, expr]), plain + 1.0
    program = Program([expr], SENSOR_INDEX, DEMON_INDEX)  # type: ignore[list-item]
    sensors = np.zeros((1, len(SENSORS)))
    sensors[0, 0] = 0.5
    assert program.evaluate(sensors)[0, 0] == pytest.approx(plain, rel=1e-15)
