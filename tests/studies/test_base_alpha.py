"""The sweep that chose the thesis control demon's step size (`horde.studies.base_alpha`,
docs/autostep-exact.md): it changes `base`'s alpha and nothing else, and measures what `horde run` measures."""

from __future__ import annotations

import numpy as np
import pytest

from horde.core.experiment import run_trial
from horde.scenarios import find_scenario
from horde.spec import RunSpec
from horde.studies.base_alpha import exact_checks, markdown, thesis_criterion, trial, with_base_alpha


def short(name: str, episodes: int, rollouts: int = 2000) -> RunSpec:
    data = find_scenario(name).model_dump(by_alias=True)
    data["protocol"].update(trials=2, episodes=episodes)
    if data["protocol"]["evaluation"]["rollouts"]:
        data["protocol"]["evaluation"]["rollouts"] = rollouts
    return RunSpec.model_validate(data)


def test_with_base_alpha_changes_that_demon_s_alpha_and_nothing_else() -> None:
    spec = find_scenario("experiment1")
    changed = with_base_alpha(spec, 0.007)
    assert [d.alpha for d in changed.demons] == [0.007, spec.demons[1].alpha]
    body, other = spec.model_dump(), changed.model_dump()
    body["demons"][0].pop("alpha"), other["demons"][0].pop("alpha")
    assert body == other


def test_a_trial_measures_what_horde_run_measures_plus_the_exact_answers() -> None:
    """The same predictions, Monte-Carlo truths (the same generator: the exact solve draws nothing) and steps
    as `experiment.run_trial`, and exact answers that the Monte-Carlo truth agrees with."""
    spec = short("experiment1", episodes=300)
    found = trial(spec, 1, exact_answers=True)
    expected = run_trial(spec, 1)
    assert found["predictions"] == expected.predictions
    assert found["truths"] == {name: t.mean for name, t in expected.truths.items()}
    assert found["steps"] == expected.steps and found["episodes"] == 300
    for name, truth in expected.truths.items():
        assert abs(found["exact"][name] - truth.mean) < 5 * truth.stderr, name
    assert found["cpu"] > 0 and found["wall"] > 0


def test_a_control_trial_counts_the_test_runs_as_horde_run_does() -> None:
    spec = short("experiment3", episodes=60)
    found = trial(spec, 0, exact_answers=False)
    expected = run_trial(spec, 0)
    assert found["counts"] == expected.counts.model_dump()  # type: ignore[union-attr]
    assert found["exact"] == {} and found["truths"] == {}
    assert thesis_criterion({"scenario": "experiment3", "alpha": 0.1, "trials": [found, found]}).count("/") == 2


def test_the_report_by_hand() -> None:
    """Two made-up trials of experiment1: base's error is that of the mean over trials; steps_to_end's
    thesis criterion is its mean prediction against its mean Monte-Carlo truth."""
    trials = [
        {"predictions": {"base": -0.11, "steps_to_end": 40.0}, "exact": {"base": -0.1, "steps_to_end": 41.0},
         "truths": {"steps_to_end": 42.0}, "counts": None, "episodes": 10, "steps": 300, "wall": 1.0, "cpu": 0.5},
        {"predictions": {"base": -0.25, "steps_to_end": 50.0}, "exact": {"base": -0.2, "steps_to_end": 49.0},
         "truths": {"steps_to_end": 48.0}, "counts": None, "episodes": 10, "steps": 700, "wall": 2.0, "cpu": 1.5},
    ]  # fmt: skip
    result = {"scenario": "experiment1", "alpha": 0.02, "trials": trials}
    base, steps = exact_checks(result)
    assert base.error == pytest.approx(0.2)  # means -0.18 against -0.15
    np.testing.assert_allclose(base.errors, [0.1, 0.25])
    assert not base.holds and not base.probability
    assert steps.error == pytest.approx(0.0) and steps.holds
    assert thesis_criterion(result) == "steps_to_end 45.00 vs 45.00: 0.00 %"
    row = markdown([result]).splitlines()[2]
    assert row.startswith("| experiment1 | 0.02 | -0.1500 | -0.1800 | 20.00 % **no** | 10.0 to 25 % |")
    assert row.endswith("| 1,000 | 3.0 / 2.0 |")
