"""The sweep that chose the thesis control demon's step size (`horde.studies.base_alpha`,
docs/autostep-exact.md): it changes `base`'s alpha and nothing else, and measures what `horde run` measures."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from horde.core.experiment import run_trial
from horde.scenarios import find_scenario
from horde.spec import RunSpec
from horde.studies.base_alpha import (
    SCENARIOS,
    choose,
    exact_checks,
    label,
    load,
    markdown,
    meets,
    standard_error,
    thesis_criterion,
    trial,
    with_base_alpha,
)

MEASURED = Path(__file__).resolve().parents[2] / "docs" / "studies" / "base-alpha.jsonl"


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
    assert standard_error(base) == pytest.approx(0.02 / 0.15)  # gaps -0.01, -0.05: sd 0.04 / sqrt 2, / sqrt 2
    row = markdown([result]).splitlines()[2]
    assert row.startswith("| experiment1 | 0.02 | -0.1500 | -0.1800 | 20.00 % **no** | 13.3 % | 10.0 to 25 % |")
    assert row.endswith("| **no** | 1,000 | 3.0 / 2.0 |")


def test_the_rule_wants_the_mean_within_the_bound_and_its_noise_below_it() -> None:
    def result(base: list[tuple[float, float]], counts: list[int] | None = None) -> dict[str, object]:
        trials = [
            {"predictions": {"base": p, "steps_to_end": 50.0}, "exact": {"base": e, "steps_to_end": 50.0},
             "truths": {"steps_to_end": 50.5}, "counts": None}
            for p, e in base
        ]  # fmt: skip
        return {"scenario": "experiment1", "alpha": 0.01, "trials": trials}

    assert meets(result([(-0.101, -0.1), (-0.099, -0.1)]))
    assert not meets(result([(-0.2, -0.1), (0.0, -0.1)])), "the mean holds, by luck: its standard error is 100 %"
    assert not meets(result([(-0.103, -0.1), (-0.097, -0.1)])), "standard error 3 %: more than half the bound"
    assert meets(result([(-0.102, -0.1), (-0.098, -0.1)])), "standard error 2 %"
    assert not meets(result([(-0.11, -0.1), (-0.11, -0.1)])), "10 % off"
    control = {"scenario": "experiment3", "alpha": 0.01, "trials": [{"counts": {"positive": 49, "negative": 1,
               "none": 0}}, {"counts": {"positive": 48, "negative": 2, "none": 0}}]}  # fmt: skip
    assert not meets(control), "97 positive of 100"
    control["trials"][0]["counts"]["positive"] = 50  # type: ignore[index]
    assert meets(control)


def test_the_shipped_base_demons_carry_the_alpha_the_measured_sweep_chooses() -> None:
    """The sweep's results as measured (docs/studies/base-alpha.jsonl, written by `--json`; the table and
    figure of docs/autostep-exact.md come from it): its rule picks one alpha, and every shipped thesis scenario
    gives its `base` demon that alpha and leaves the others as they were."""
    results = load(MEASURED)
    assert {r["scenario"] for r in results} == set(SCENARIOS)
    assert all(len(r["trials"]) == 10 and r["trials"][0]["episodes"] == 10_000 for r in results)
    chosen = choose(results)
    assert chosen == 0.002
    for name in SCENARIOS:
        spec = find_scenario(name)
        alphas = {d.name: d.alpha for d in spec.demons}
        assert alphas.pop("base") == chosen, name
        assert alphas in ({"steps_to_end": 0.05}, {"critical": 0.05}, {"colour": 0.5}, {}), name
        assert spec.learning.alpha == 0.1, name


def test_other_seeds_are_kept_apart_and_named(tmp_path: Path) -> None:
    """`--seeds` runs the protocol from other seeds: the results file keeps one object per scenario x alpha x
    seed (the last of each; a line without a seed is the scenario's own), and the table names a seed that is not
    the scenario's own."""
    lines = [
        {"scenario": "experiment1", "alpha": 0.01, "trials": [], "mark": "own, old"},
        {"scenario": "experiment1", "alpha": 0.01, "seed": 11, "trials": [], "mark": "seed 11"},
        {"scenario": "experiment1", "alpha": 0.01, "trials": [], "mark": "own, new"},
        {"scenario": "experiment1", "alpha": 0.01, "seed": 1, "trials": [], "mark": "own seed, named"},
    ]
    path = tmp_path / "sweep.jsonl"
    path.write_text("\n".join(json.dumps(line) for line in lines) + "\n")
    found = load(path)
    assert [r["mark"] for r in found] == ["own seed, named", "seed 11"]  # a line without a seed ran the own
    assert [label(r) for r in found] == ["experiment1", "experiment1 (seed 11)"]
