"""Table features and initial weights in the spec: what is refused, and where the error points."""

from __future__ import annotations

from typing import Any

import pytest
from pydantic import ValidationError

from horde.spec import RunSpec
from horde.worlds.gym_spaces import resolve_world

TABLE = [[i, i, 7] for i in range(6)] + [[6, 7, 7]]
THETA0 = [1, 1, 1, 1, 1, 1, 10, 1]


def spec(features: dict[str, Any] | None = None, learning: dict[str, Any] | None = None, **demon: Any) -> RunSpec:
    """A Baird spec, validated and its Gymnasium world resolved (where the checks that read its sensors run)."""
    return resolve_world(
        RunSpec.model_validate(
            {
                "world": {"kind": "gymnasium", "id": "horde/Baird-v0"},
                "features": features or {"kind": "table", "sensor": "state", "table": TABLE},
                "behaviour": {"kind": "fixed", "probabilities": [6 / 7, 1 / 7]},
                "learning": learning or {},
                "demons": [
                    {"name": "d", "learner": "td", "policy": {"kind": "fixed", "probabilities": [0, 1]}, **demon}
                ],
            }
        )
    )


def problem(**kwargs: Any) -> tuple[tuple[Any, ...], str]:
    with pytest.raises(ValidationError) as info:
        spec(**kwargs)
    error = info.value.errors()[0]
    return tuple(error["loc"]), error["msg"]


def test_a_valid_baird_spec_has_eight_weights_and_three_listed_indices() -> None:
    features = spec(initial_weights=THETA0).features
    assert features.state_size() == 8 and features.active_count() == 3 and features.has_repeats()


@pytest.mark.parametrize(
    ("features", "loc", "words"),
    [
        ({"kind": "table", "sensor": "state"}, ("features",), "need a sensor and a table"),
        ({"kind": "table", "sensor": "state", "table": [[0, 1], [1]]}, ("features",), "same number of indices"),
        ({"kind": "table", "sensor": "state", "table": [[0, -1]]}, ("features", "table", 0, 1), "greater than"),
        ({"kind": "table", "sensor": "speed", "table": TABLE}, ("features", "sensor"), "unknown sensor 'speed'"),
        ({"kind": "table", "sensor": "state", "table": TABLE[:3]}, ("features", "table"), "0 to 2 only"),
        ({"kind": "constant", "table": TABLE}, ("features",), "belong to kind = 'table'"),
    ],
)
def test_bad_tables_are_refused_naming_the_field(features: dict[str, Any], loc: tuple[Any, ...], words: str) -> None:
    where, message = problem(features=features)
    assert where[: len(loc)] == loc and words in message, (where, message)


def test_initial_weights_must_fit_the_demon() -> None:
    where, message = problem(initial_weights=[1.0, 2.0])
    assert where == ("demons", 0, "initial_weights") and "has 8 weights" in message
    where, message = problem(learner="gq", initial_weights=THETA0)  # GQ: one block of 8 per action
    assert where == ("demons", 0, "initial_weights") and "has 16 weights; initial_weights lists 8" in message
    where, _ = problem(initial_weights=[*THETA0[:7], float("nan")])
    assert where == ("demons", 0, "initial_weights", 7)
    where, message = problem(initial_weights=THETA0, reset="episode")
    assert where == ("demons", 0) and "initial_weights and reset" in message


def test_adaptive_step_sizes_take_features_of_value_2() -> None:
    """Autostep and TIDBD take each feature's value (the engine equals the reference on them:
    test_baird_engine.py), so a table that lists an index twice is no longer refused."""
    assert spec(step_size="autostep").demons[0].step_size == "autostep"
    assert spec(learning={"step_size": "tidbd"}).features.binary is False
