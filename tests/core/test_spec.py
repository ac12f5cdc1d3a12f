"""The data model (DESIGN sections 2-4): invalid specs fail with errors that name the problem (a 422)."""

from __future__ import annotations

from typing import Any

import pytest
from pydantic import BaseModel, ValidationError

import horde.spec as spec_module
from grids import lamp, lamp_terminal
from horde.spec import (
    IMPOSSIBLE_START,
    DemonSpec,
    IfExpr,
    PolicySpec,
    RunSpec,
    SensorExpr,
    WorldSpec,
    check_demon_graph,
)

WORLD: dict[str, Any] = {
    "regions": [
        {"name": "goal", "kind": "terminal", "rect": [400, 400, 500, 500], "reward": 1},
        {"name": "crit", "kind": "zone", "rect": [0, 0, 200, 200]},
    ]
}


def run(*demons: dict[str, Any], **fields: Any) -> RunSpec:
    return RunSpec.model_validate({"world": WORLD, "demons": list(demons), **fields})


def errors_of(call, *args, **kwargs) -> list[dict[str, Any]]:
    with pytest.raises(ValidationError) as info:
        call(*args, **kwargs)
    return info.value.errors()


def message(call, *args, **kwargs) -> str:
    return " | ".join(e["msg"] for e in errors_of(call, *args, **kwargs))


def test_a_valid_spec_orders_demons_after_what_they_read():
    spec = run(
        {"name": "echo", "learner": "gtd", "cumulant": {"prediction": "steps"}},
        {"name": "steps", "learner": "gtd", "policy": {"of": "base"}, "cumulant": 1},
        {"name": "base", "policy": "softmax", "cumulant": {"sensor": "reward"}},
        {"name": "cond", "features": {"kind": "stripes", "condition": {"demon": "echo", "thresholds": [0]}}},
        behaviour={"kind": "softmax", "demon": "base"},
    )
    order = check_demon_graph(spec)
    assert sorted(order) == ["base", "cond", "echo", "steps"]
    assert order.index("base") < order.index("steps") < order.index("echo") < order.index("cond")


@pytest.mark.parametrize(
    ("demons", "cycle"),
    [
        ([{"name": "a", "cumulant": {"prediction": "a"}}], "a -> a"),
        (
            [{"name": "a", "cumulant": {"prediction": "b"}}, {"name": "b", "outcome": {"prediction": "a"}}],
            "a -> b -> a",
        ),
        (
            [
                {"name": "a", "policy": {"of": "b"}},
                {"name": "b", "continuation": {"min": [1, {"prediction": "c"}]}},
                {
                    "name": "c",
                    "features": {"kind": "constant", "condition": {"demon": "a", "thresholds": [0]}},
                },
            ],
            "a -> b -> c -> a",
        ),
    ],
    ids=["self", "two predictions", "policy, prediction and condition"],
)
def test_cycles_of_demons_are_rejected_with_the_cycle_named(demons, cycle):
    text = message(run, *demons)
    assert "cycle" in text and cycle in text, text


def test_a_cycle_beside_valid_demons_names_only_the_cycle():
    text = message(
        run,
        {"name": "ok", "cumulant": 1},
        {"name": "x", "cumulant": {"prediction": "y"}},
        {"name": "y", "cumulant": {"add": [{"prediction": "ok"}, {"prediction": "x"}]}},
    )
    assert "x -> y -> x" in text and "ok ->" not in text, text


@pytest.mark.parametrize(
    ("demon", "named"),
    [
        ({"name": "a", "cumulant": {"prediction": "ghost"}}, ["'a'", "unknown demon 'ghost'"]),
        ({"name": "a", "policy": {"of": "ghost"}}, ["'a'", "unknown demon 'ghost'"]),
        (
            {"name": "a", "features": {"kind": "grid", "condition": {"demon": "ghost", "thresholds": [0]}}},
            ["'a'", "unknown demon 'ghost'"],
        ),
        (
            {"name": "a", "outcome": {"sensor": "in:nowhere"}},
            ["'a'", "outcome", "unknown sensor 'in:nowhere'"],
        ),
        (
            {"name": "a", "continuation": {"if": {"sensor": "colour"}, "then": 0, "else": 1}},
            ["'a'", "continuation", "unknown sensor 'colour'"],
        ),
    ],
)
def test_unknown_demon_and_sensor_references_are_named(demon, named):
    text = message(run, demon)
    for part in named:
        assert part in text, (part, text)


def test_unknown_sensor_error_lists_the_known_sensors():
    text = message(run, {"name": "a", "cumulant": {"sensor": "in:gaol"}})
    assert "in:goal" in text and "in:crit" in text and "terminal" in text


def test_behaviour_references_are_checked():
    assert "unknown demon 'ghost'" in message(run, {"name": "a"}, behaviour={"kind": "greedy", "demon": "ghost"})
    text = message(run, {"name": "v", "learner": "gtd"}, behaviour={"kind": "softmax", "demon": "v"})
    assert "'v'" in text and "action values" in text
    test = {"runs": 1, "behaviour": {"kind": "greedy", "demon": "ghost"}}
    assert "ghost" in message(run, {"name": "a"}, protocol={"test": test})


@pytest.mark.parametrize(
    "continuation",
    [1.5, -0.1, {"sensor": "x"}, {"add": [{"sensor": "in:crit"}, 0.5]}, {"mul": [{"sensor": "bump"}, -1]}],
)
def test_continuation_outside_zero_one_is_rejected(continuation):
    text = message(run, {"name": "a", "continuation": continuation})
    assert "'a'" in text and "continuation" in text and "[0, 1]" in text, text


@pytest.mark.parametrize(
    "continuation",
    [
        0.0,
        1.0,
        {"sensor": "in:crit"},
        {"if": {"sensor": "in:crit"}, "then": 0, "else": 1},
        {"mul": [0.5, {"sensor": "bump"}]},
        {"max": [0.2, {"sensor": "terminal"}]},
    ],
)
def test_continuation_within_zero_one_is_accepted(continuation):
    assert run({"name": "a", "continuation": continuation}).demons[0].name == "a"


def test_discount_outside_zero_one_names_the_field():
    errors = errors_of(DemonSpec.model_validate, {"name": "a", "discount": 1.2})
    assert [e["loc"] for e in errors] == [("discount",)]


def test_duplicate_names_are_rejected():
    assert "'a' appears twice" in message(run, {"name": "a"}, {"name": "a", "cumulant": 1})
    regions = [{"name": "r", "kind": "zone", "rect": [0, 0, 1, 1]}] * 2
    assert "unique: r" in message(WorldSpec.model_validate, {"regions": regions})
    colors = [{"name": "red", "value": 1, "probability": 0.5}] * 2
    lamp = {"name": "lamp", "kind": "indicator", "rect": [0, 0, 1, 1], "colors": colors}
    assert "repeated colour" in message(WorldSpec.model_validate, {"regions": [lamp]})


@pytest.mark.parametrize(
    ("spec", "loc"),
    [
        ({"demons": [{"name": "a", "cumulent": 1}]}, ("demons", 0, "cumulent")),
        ({"world": {"widht": 10}}, ("world", "widht")),
        (
            {"world": {"regions": [{"name": "z", "kind": "zone", "rect": [0, 0, 1, 1], "color": "red"}]}},
            ("world", "regions", 0, "color"),
        ),
        ({"learning": {"lambda": 0.5, "gamma": 0.9}}, ("learning", "gamma")),
        ({"seed": 1, "speed": 3}, ("speed",)),
    ],
)
def test_extra_keys_are_forbidden_and_named(spec, loc):
    errors = errors_of(RunSpec.model_validate, spec)
    assert [(e["type"], e["loc"]) for e in errors] == [("extra_forbidden", loc)]


def test_extra_keys_inside_expressions_are_forbidden():
    errors = errors_of(DemonSpec.model_validate, {"name": "a", "cumulant": {"sensor": "x", "scale": 2}})
    assert any(e["type"] == "extra_forbidden" and e["loc"][-1] == "scale" for e in errors), errors


def test_expressions_parse_into_their_models():
    demon = DemonSpec.model_validate(
        {"name": "a", "continuation": {"if": {"sensor": "in:crit"}, "then": 0, "else": {"sensor": "bump"}}}
    )
    assert isinstance(demon.continuation, IfExpr)
    assert demon.continuation.if_ == SensorExpr(sensor="in:crit")
    assert demon.continuation.then == 0.0
    assert demon.continuation.else_ == SensorExpr(sensor="bump")


def test_kind_rules():
    assert "action values" in message(DemonSpec.model_validate, {"name": "a", "learner": "gtd", "policy": "greedy"})
    assert "sum to 1" in message(PolicySpec.model_validate, {"kind": "fixed", "probabilities": [0.5, 0.5, 0.5, 0]})
    assert "needs probabilities" in message(PolicySpec.model_validate, "fixed")
    terminal = {"name": "t", "kind": "terminal", "rect": [0, 0, 1, 1]}
    assert "needs a reward" in message(WorldSpec.model_validate, {"regions": [terminal]})
    assert "rect" in message(
        WorldSpec.model_validate, {"regions": [{"name": "z", "kind": "zone", "rect": [1, 0, 0, 1]}]}
    )
    inside = {
        "start": [150, 250],
        "regions": [{"name": "wall", "kind": "obstacle", "rect": [100, 200, 200, 300]}],
    }
    assert "start lies inside obstacle 'wall'" in message(WorldSpec.model_validate, inside)
    indicator = lamp([0, 0, 1, 1], y=(1, 0.5), p=(-1, 0.5))
    pit = lamp_terminal("pit", [2, 2, 3, 3], y=1)
    assert "exactly the colours" in message(WorldSpec.model_validate, {"regions": [indicator, pit]})


def test_policy_shorthands():
    assert PolicySpec.model_validate("softmax") == PolicySpec(kind="softmax")
    assert PolicySpec.model_validate({"of": "base"}) == PolicySpec(kind="of", demon="base")


def test_every_spec_model_is_frozen_and_forbids_unknown_keys():
    """The project's rule (spec.py's docstring): a spec never changes once validated, and a typo is a 422.

    Checked on every model the module defines, so a new model written on BaseModel (not `Model`) or with its own
    config fails here."""
    models = [
        value
        for value in vars(spec_module).values()
        if isinstance(value, type)
        and issubclass(value, BaseModel)
        and value.__module__.startswith(spec_module.__name__)
    ]
    assert len(models) > 20
    loose = [m.__name__ for m in models if m.model_config.get("frozen") is not True]
    lax = [m.__name__ for m in models if m.model_config.get("extra") != "forbid"]
    assert loose == [] and lax == [], (loose, lax)


def test_only_of_policies_name_a_demon() -> None:
    """Found by schemathesis: {"demon": "A"} with the default kind once reached the engine."""
    with pytest.raises(ValidationError, match="only 'of' policies name a demon"):
        PolicySpec.model_validate({"demon": "A"})
    assert PolicySpec.model_validate({"of": "A"}).demon == "A"


# A start rectangle [100, 200, 300, 300] covered by a wall on its left half and a goal on its right half.
COVERED: dict[str, Any] = {
    "start": [100, 200, 300, 300],
    "regions": [
        {"name": "wall", "kind": "obstacle", "rect": [0, 150, 200, 300]},
        {"name": "goal", "kind": "terminal", "rect": [200, 200, 400, 350], "reward": 1},
    ],
}


def test_a_start_rectangle_without_a_free_cell_is_rejected_at_world_start():
    errors = errors_of(RunSpec.model_validate, {"world": COVERED, "demons": [{"name": "a"}]})
    assert [e["loc"] for e in errors] == [("world", "start")]
    assert errors[0]["msg"] == IMPOSSIBLE_START


def test_a_start_rectangle_with_one_free_sliver_is_accepted():
    # Shrink the goal by 1 at the top-left corner's column: the strip x in [200, 201) stays free.
    sliver = {**COVERED, "regions": [COVERED["regions"][0], {**COVERED["regions"][1], "rect": [201, 200, 400, 350]}]}
    WorldSpec.model_validate(sliver)
    # A zone (not an obstacle nor a terminal) over the whole rectangle leaves it free.
    zone = {"start": [100, 200, 300, 300], "regions": [{"name": "z", "kind": "zone", "rect": [0, 0, 500, 500]}]}
    WorldSpec.model_validate(zone)
