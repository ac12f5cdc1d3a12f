"""Demon families: one spec entry expands into the product of its lists, bounded before anything is built."""

from __future__ import annotations

import copy
from typing import Any

import pytest
from pydantic import ValidationError

from horde.core.simulation import Simulation
from horde.spec import MAX_DEMONS, RunSpec


def spec_body() -> dict[str, Any]:
    return {
        "world": {"regions": [{"name": "z1", "kind": "zone", "rect": [0, 0, 100, 100]}]},
        "features": {"kind": "tiles", "tilings": 2, "tiles": 2},
        "behaviour": "uniform",
        "demons": [{"name": "plain", "learner": "td", "policy": "uniform", "cumulant": 1}],
        "families": [
            {
                "name": "{s}_g{gamma}",
                "over": {"s": ["in:z1", "bump"], "gamma": [0.5, 0.9]},
                "demon": {"learner": "td", "policy": "uniform", "cumulant": {"sensor": "{s}"}, "discount": "{gamma}"},
            }
        ],
    }


def test_a_family_expands_into_the_product_of_its_lists() -> None:
    spec = RunSpec.model_validate(spec_body())
    assert [d.name for d in spec.demons] == ["plain", "in_z1_g0.5", "in_z1_g0.9", "bump_g0.5", "bump_g0.9"]
    assert [d.discount for d in spec.demons[1:]] == [0.5, 0.9, 0.5, 0.9], "a whole '{gamma}' keeps its number"
    assert spec.demons[3].cumulant.sensor == "bump"  # type: ignore[union-attr]
    assert spec.families == [], "expanded once: the spec reads back as plain demons"
    assert RunSpec.model_validate(spec.model_dump(by_alias=True)) == spec
    sim = Simulation(spec)
    sim.run(50)
    assert sim.horde.names == [d.name for d in spec.demons]


def errors(body: dict[str, Any]) -> list[tuple[tuple[Any, ...], str]]:
    with pytest.raises(ValidationError) as info:
        RunSpec.model_validate(body)
    return [(e["loc"], e["msg"]) for e in info.value.errors()]


def test_a_family_past_the_demon_limit_names_its_lists() -> None:
    body = spec_body()
    body["families"][0]["over"]["gamma"] = [0.5] * (MAX_DEMONS // 2 + 1)
    [(loc, msg)] = errors(body)
    assert loc == ("families", 0, "over") and f"more than {MAX_DEMONS}" in msg


def test_families_and_demons_together_past_the_limit_name_families() -> None:
    body = spec_body()
    body["families"][0]["over"]["gamma"] = [0.5] * (MAX_DEMONS // 2)  # 2 x 5000 = the limit, plus "plain"
    [(loc, msg)] = errors(body)
    assert loc == ("families",) and str(MAX_DEMONS + 1) in msg


@pytest.mark.parametrize(
    ("change", "field", "words"),
    [
        (lambda f: f.update(name="{s}"), "name", "must use every list of over as a {placeholder} (missing: gamma)"),
        (lambda f: f.update(name="{s}_{nope}_{gamma}"), "name", "(nope is not)"),
        (lambda f: f.update(name="<b>{s}{gamma}"), "name", "combination 1 of over does not"),
        (lambda f: f["demon"].update(discount="{s}"), None, "demon: combination 1 of over: discount"),
        (lambda f: f["demon"].update(name="x"), None, "takes its name"),
    ],
)
def test_a_bad_family_is_a_422_naming_the_field_and_the_rule(change, field, words) -> None:
    body = copy.deepcopy(spec_body())
    change(body["families"][0])
    [(loc, msg)] = errors(body)
    assert loc == ("families", 0, field) if field else loc == ("families", 0)
    assert words in msg


def test_a_family_422_never_echoes_the_pattern_or_the_names_made_of_it() -> None:
    for pattern in ("<script>alert(1)</script>{s}{gamma}", "SECRET_{s}", "SECRET_{s}_{gamma}_{oops}"):
        body = copy.deepcopy(spec_body())
        body["families"][0]["name"] = pattern
        [(_, msg)] = errors(body)
        assert "script" not in msg and "SECRET" not in msg, msg
    body = copy.deepcopy(spec_body())
    body["families"][0]["name"] = "SECRET_{s}_{gamma}"
    body["families"][0]["demon"]["discount"] = "{s}"
    [(_, msg)] = errors(body)
    assert "SECRET" not in msg and "in_z1" not in msg, msg
