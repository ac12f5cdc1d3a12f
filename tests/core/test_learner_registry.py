"""The learner registry: every learner a demon may name has its kernel, its oracle and its line of docs.

A learner is one module of `horde.core.learners` that registers itself (`horde.spec.learners`); what the spec,
the API schema, the dashboard (GET /api/learners: tests/server/test_learner_choices.py) and the README say of
it comes from that registration. These checks fail for a learner registered without the rest.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from horde.core.learners import KERNELS, kernel_for
from horde.core.reference import ReferenceHorde
from horde.spec import DemonSpec, learner_info, learner_names
from horde.spec.demons import _learner_choices

README = Path(__file__).resolve().parents[2] / "README.md"
EXPECTED = ["etd", "gq", "gtd", "gtd1", "gtd2", "td", "tdrc", "true_online_gtd", "true_online_td"]


def test_the_registry_holds_every_learner_with_a_kernel_for_each_of_its_step_sizes() -> None:
    assert list(learner_names()) == EXPECTED
    pairs = {(k.learner, k.step_size) for k in KERNELS.values()}
    assert pairs == {(n, m) for n in learner_names() for m in learner_info(n).step_sizes}
    assert len({k.code for k in KERNELS.values()}) == len(KERNELS)
    for name in learner_names():
        assert kernel_for(name).learner == name
        info = learner_info(name)
        assert info.text and "\n" not in info.text and len(info.text) < 80 and info.paper


def test_the_schema_and_the_spec_take_their_names_from_the_registry() -> None:
    schema: dict[str, object] = {}
    _learner_choices(schema)
    assert schema["enum"] == EXPECTED
    assert DemonSpec.model_json_schema()["properties"]["learner"]["enum"] == EXPECTED
    with pytest.raises(ValueError, match="unknown learner 'lstd'"):
        DemonSpec.model_validate({"name": "d", "learner": "lstd"})


def test_the_oracle_steps_every_learner() -> None:
    """The plain oracle has a step for each (a learner without one fails here, not in a long test)."""
    from horde.spec import RunSpec

    demons = [{"name": f"d_{n}", "learner": n, "policy": "uniform", "cumulant": 1.0} for n in learner_names()]
    spec = RunSpec.model_validate({"features": {"kind": "grid", "tiles": 5}, "demons": demons})
    ref = ReferenceHorde(spec)
    sensors = dict.fromkeys(spec.world.sensor_names(), 0.0)
    ref.observe(0.0, 0.0, sensors)
    ref.learn(0, 0.25, 0.0, 100.0, {**sensors, "y": 100.0}, False)
    assert [d.delta for d in ref.demons.values()] == [1.0] * len(EXPECTED)  # zero weights: delta = r
    # every learner moved its weights (GTD2's and the original GTD's theta follow w, still 0 here: w moved)
    assert all(d.theta.any() or d.w.any() for d in ref.demons.values()), "every learner moved its weights"


def test_the_readme_explains_every_learner() -> None:
    """The docs name each registered learner (the README's "Learners and step sizes")."""
    text = README.read_text()
    section = text[text.index("## Learners and step sizes") : text.index("## The dashboard")]
    missing = [name for name in learner_names() if f"`{name}`" not in section]
    assert missing == [], f"README's learner section does not name {missing}"
