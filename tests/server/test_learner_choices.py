"""Learners and step-size modes over the API: the effective step size in the demon table, and 422s that
name the field for an undefined learner x step-size combination or an out-of-range parameter."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest
from fastapi.testclient import TestClient

from horde.spec import learner_names

from .helpers import locs, make_spec, messages

BASE = {"name": "base", "policy": {"kind": "softmax", "temperature": 1.0}, "cumulant": {"sensor": "reward"}}


def demon(**fields: Any) -> dict[str, Any]:
    return {"name": "d", "policy": {"of": "base"}, "outcome": {"sensor": "in:goal"}, **fields}


def test_the_demon_table_shows_each_demon_its_step_size(client: TestClient, create_run: Callable[..., str]) -> None:
    demons = [BASE, demon(learner="td", step_size="autostep", alpha=0.2), {**demon(learner="true_online_td"),
              "name": "t"}]  # fmt: skip
    run_id = create_run(make_spec(demons=demons, learning={"alpha": 0.1}))
    assert client.post(f"/api/runs/{run_id}/step", json={"steps": 300}).status_code == 200
    table = {d["name"]: d["metrics"] for d in client.get(f"/api/runs/{run_id}/demons").json()}
    assert table["t"]["step_size"] == pytest.approx(0.1)  # constant: alpha as given
    assert table["base"]["step_size"] == pytest.approx(0.1)
    adapted = table["d"]["step_size"]
    assert adapted is not None and adapted > 0.0 and adapted != pytest.approx(0.2)  # tuned itself online


@pytest.mark.parametrize(
    ("fields", "loc", "words"),
    [
        ({"learner": "gq", "step_size": "autostep"}, ["demons", 1], "not defined for learner 'gq'"),
        ({"learner": "etd", "step_size": "tidbd"}, ["demons", 1], "derived for TD(lambda) only"),
        ({"learner": "td", "step_size": "sgd"}, ["demons", 1, "step_size"], "Input should be"),
        ({"learner": "td", "step_size": "autostep", "meta_step": 2.0}, ["demons", 1, "meta_step"], "less than"),
        ({"learner": "lstd"}, ["demons", 1, "learner"], "unknown learner 'lstd' (known: etd, gq, gtd, gtd1, gtd2, td"),
        (
            {"learner": "tdrc", "parameters": {"gamma": 1}},
            ["demons", 1, "parameters", "gamma"],
            "takes no parameter 'gamma' (its parameters: beta, eta)",
        ),
        ({"learner": "tdrc", "parameters": {"beta": -1}}, ["demons", 1, "parameters", "beta"], "must lie in [0, 1000]"),
        ({"learner": "gtd", "parameters": {"beta": 1}}, ["demons", 1, "parameters", "beta"], "(its parameters: none)"),
        ({"learner": "gtd1", "lambda": 0.5}, ["demons", 1, "lambda"], "'gtd1' is defined for lambda = 0 only"),
    ],
)
def test_undefined_combinations_and_bad_parameters_are_422_naming_the_field(
    client: TestClient, fields: dict[str, Any], loc: list[Any], words: str
) -> None:
    response = client.post("/api/runs", json=make_spec(demons=[BASE, demon(**fields)]))
    assert any(problem[-len(loc) :] == loc for problem in locs(response)), locs(response)
    assert words in messages(response)


def test_the_learners_route_lists_the_registry(client: TestClient) -> None:
    """GET /api/learners: every declared learner, with what the dashboard shows and what a demon may set."""
    learners = {item["name"]: item for item in client.get("/api/learners").json()}
    assert sorted(learners) == sorted(learner_names()) and "tdrc" in learners
    assert learners["gq"]["action_values"] and not learners["gtd"]["action_values"]
    assert learners["td"]["step_sizes"] == ["constant", "autostep", "tidbd"]
    assert learners["td"]["traces"] and learners["gtd"]["traces"] and learners["gtd2"]["traces"], "their (lambda)"
    assert not learners["gtd1"]["traces"], "the original GTD: lambda 0 only, the editor shows lambda 0 fixed"
    beta = {p["name"]: p for p in learners["tdrc"]["parameters"]}["beta"]
    assert (beta["default"], beta["low"], beta["high"]) == (1.0, 0.0, 1000.0)
    for item in learners.values():
        assert item["text"] and "\n" not in item["text"] and len(item["text"]) < 80, item


def test_a_learners_parameter_reaches_its_demon(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run(make_spec(demons=[BASE, demon(learner="tdrc", parameters={"beta": 0.5})]))
    spec = client.get(f"/api/runs/{run_id}").json()["spec"]
    assert spec["demons"][1]["parameters"] == {"beta": 0.5}
    assert client.post(f"/api/runs/{run_id}/step", json={"steps": 50}).status_code == 200


LEARNING_PROBLEMS = [({"autostep_tau": 0.5}, "autostep_tau"), ({"meta_step": -1}, "meta_step"),
                     ({"step_size": "adam"}, "step_size")]  # fmt: skip


@pytest.mark.parametrize(("learning", "field"), LEARNING_PROBLEMS)
def test_learning_defaults_out_of_range_are_422(client: TestClient, learning: dict[str, Any], field: str) -> None:
    response = client.post("/api/runs", json=make_spec(learning=learning))
    assert any(problem[-2:] == ["learning", field] for problem in locs(response)), locs(response)


def test_an_adaptive_default_applies_where_it_is_defined(client: TestClient, create_run: Callable[..., str]) -> None:
    """[learning] step_size = "autostep": td demons adapt, the others (gq here) keep constant step sizes."""
    demons = [BASE, demon(learner="td")]
    run_id = create_run(make_spec(demons=demons, learning={"step_size": "autostep", "alpha": 0.1}))
    client.post(f"/api/runs/{run_id}/step", json={"steps": 300})
    table = {d["name"]: d["metrics"] for d in client.get(f"/api/runs/{run_id}/demons").json()}
    assert table["base"]["step_size"] == pytest.approx(0.1)
    assert table["d"]["step_size"] != pytest.approx(0.1)
