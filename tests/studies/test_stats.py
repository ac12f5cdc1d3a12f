"""The bootstrap confidence interval on data whose answer is known."""

from __future__ import annotations

import numpy as np
import pytest

from horde.studies.stats import bootstrap_mean, mark_best, summarize_configuration


def test_identical_runs_give_a_point_interval() -> None:
    mean, low, high = bootstrap_mean(np.array([2.0, 2.0, 2.0]))
    assert (float(mean), float(low), float(high)) == (2.0, 2.0, 2.0)


def test_two_values_bound_the_interval_by_hand() -> None:
    # resampling [0, 1] twice gives means 0, 0.5 or 1 with probabilities 1/4, 1/2, 1/4
    mean, low, high = bootstrap_mean(np.array([0.0, 1.0]))
    assert float(mean) == 0.5 and float(low) == 0.0 and float(high) == 1.0


def test_the_interval_covers_the_true_mean_about_95_percent_of_the_time() -> None:
    rng = np.random.default_rng(0)
    covered = 0
    repeats = 300
    for i in range(repeats):
        _, low, high = bootstrap_mean(rng.normal(3.0, 1.0, size=30), resamples=1000, seed=i)
        covered += bool(low <= 3.0 <= high)
    # a percentile bootstrap of 30 normal samples covers slightly under 95 %; a broken one is far off
    assert 0.88 <= covered / repeats <= 0.99


def test_bands_narrow_as_runs_grow_like_one_over_sqrt_runs() -> None:
    rng = np.random.default_rng(1)
    widths = {}
    for runs in (5, 20, 80):
        w = []
        for i in range(40):
            _, low, high = bootstrap_mean(rng.normal(0.0, 1.0, size=runs), seed=i)
            w.append(float(high - low))
        widths[runs] = float(np.mean(w))
    assert widths[5] > widths[20] > widths[80]
    # 2 * 1.96 / sqrt(runs) for a unit normal
    for runs, width in widths.items():
        assert width == pytest.approx(2 * 1.96 / np.sqrt(runs), rel=0.25)


def test_columns_are_bootstrapped_together_per_checkpoint() -> None:
    samples = np.array([[1.0, 10.0], [3.0, 10.0]])  # [R, C]
    mean, low, high = bootstrap_mean(samples)
    assert mean.tolist() == [2.0, 10.0]
    assert low.tolist() == [1.0, 10.0] and high.tolist() == [3.0, 10.0]


def _task(errors: list[float], scale: float) -> dict[str, object]:
    n = len(errors)
    return {
        "episodes": list(range(n)),
        "truth": "exact",
        "returns": [float("nan")] + [0.0] * (n - 1),
        "seconds": 1.0,
        "demons": {"a": {"error": errors, "scale": [scale] * n, "rupee": [0.0] * n, "prediction": [0.0] * n}},
    }


def test_a_configuration_summary_averages_runs_and_relative_errors() -> None:
    summary = summarize_configuration(0, {"x": 1}, [_task([4.0, 2.0, 1.0], 4.0), _task([4.0, 4.0, 3.0], 4.0)])
    assert summary.runs == 2
    assert summary.demons["a"].final.mean == [2.0]
    assert summary.demons["a"].auc.mean == [2.5]  # mean of (2 + 1) / 2 and (4 + 3) / 2
    assert summary.final.mean == [0.5]  # relative: 2 / 4
    assert summary.curve.mean == [1.0, 0.75, 0.5]


def test_the_best_configuration_has_the_lowest_final_error() -> None:
    a = summarize_configuration(0, {"x": 1}, [_task([1.0, 0.5], 1.0)])
    b = summarize_configuration(1, {"x": 2}, [_task([1.0, 0.2], 1.0)])
    mark_best([a, b])
    assert (a.best, b.best) == (False, True)


def test_test_run_counts_become_the_share_of_positive_endings() -> None:
    tasks = [_task([1.0], 1.0) | {"counts": {"positive": p, "negative": 10 - p, "none": 0}} for p in (6, 8)]
    summary = summarize_configuration(0, {}, tasks)
    positive = summary.extra["positive"]
    assert positive.mean == [0.7] and positive.low == [0.6] and positive.high == [0.8]  # type: ignore[attr-defined]
