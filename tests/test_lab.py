"""The textbook lab's catalogue (horde.lab): every experiment launches, and a set-up past a field's bound is a
SpecError naming the set-up field (a 422 over REST)."""

from __future__ import annotations

import pytest

from horde.lab import EXPERIMENTS, setup_run, setup_study
from horde.runs.errors import SpecError


def test_every_experiment_of_the_lab_makes_its_run_or_study_as_shipped() -> None:
    for entry in EXPERIMENTS:
        if entry.kind == "run":
            spec = setup_run(entry.id, {})
            assert spec.name == entry.source
        else:
            study, base = setup_study(entry.id, {})
            assert study.base == base and study.caption


def test_a_set_up_changes_the_fields_it_names() -> None:
    assert setup_run("walk-19", {"alpha": "0.05", "lambda": "0.4"}).learning.alpha == 0.05
    assert setup_run("walk-1000", {"order": "7"}).demons[1].features.order == 7  # type: ignore[union-attr]
    study, _ = setup_study("fig-12-3", {"alpha": "0.1, 0.2", "lambda": "0.9", "runs": "2"})
    assert [(a.path, a.values) for a in study.axes] == [("learning.alpha", [0.1, 0.2]), ("learning.lambda", [0.9])]
    assert study.runs == 2
    study, _ = setup_study("boyan-learners", {"alpha": "0.05"})  # a path no axis sweeps: an axis of one value
    assert study.axes[-1].path == "learning.alpha" and study.axes[-1].values == [0.05]


@pytest.mark.parametrize("experiment, setup, field", [
    ("walk-1000", {"order": "40"}, "order"), ("walk-19", {"alpha": "x"}, "alpha"),
    ("fig-9-5", {"order": "99"}, "order"),
    ("walk-19", {"beta": "1"}, "beta"), ("fig-12-3", {"lambda": "1.5"}, "lambda"), ("fig-12-3", {"runs": "0"}, "runs"),
    ("walk-19", {"runs": "3"}, "runs"),
])  # fmt: skip
def test_a_set_up_past_its_bound_is_refused_naming_its_field(
    experiment: str, setup: dict[str, str], field: str
) -> None:
    with pytest.raises(SpecError) as caught:
        (setup_run if experiment.startswith("walk") else setup_study)(experiment, setup)
    assert caught.value.problems[0].loc == ("setup", field), caught.value.problems
