"""A diverged configuration is flagged (results, CSV, plots), td = gtd at alpha_w 0 is warned of, curves export."""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path
from typing import Any

import pytest

from horde.scenarios import find_scenario
from horde.studies import plots
from horde.studies.export import curves_csv, results_csv, summary_json
from horde.studies.spec import StudySpec, expand, study_warnings
from horde.studies.stats import DIVERGED_ERROR, ConfigSummary, mark_best, summarize_configuration


def _task(errors: list[float], diverged: list[str] | None = None) -> dict[str, Any]:
    n = len(errors)
    task: dict[str, Any] = {
        "episodes": list(range(n)),
        "truth": "exact",
        "returns": [float("nan")] + [0.0] * (n - 1),
        "seconds": 1.0,
        "demons": {"a": {"error": errors, "scale": [1.0] * n, "rupee": [0.0] * n, "prediction": [0.0] * n}},
    }
    if diverged is not None:
        task["diverged"] = diverged
    return task


def _summary(index: int, *tasks: dict[str, Any]) -> ConfigSummary:
    return summarize_configuration(index, {"learning.alpha": 0.1 * (index + 1)}, list(tasks))


def test_a_run_with_a_huge_or_non_finite_error_or_a_frozen_demon_flags_its_configuration() -> None:
    assert not _summary(0, _task([1.0, 0.5, 0.2]), _task([1.0, 0.4, 0.3])).diverged
    assert not _summary(0, _task([1.0, 0.5, DIVERGED_ERROR])).diverged  # at the bound: still a (bad) fit
    assert _summary(0, _task([1.0, 0.5, 0.2]), _task([1.0, 3e3, 9.6e8])).diverged  # one run of two
    assert _summary(0, _task([1.0, math.inf, math.nan])).diverged
    assert _summary(0, _task([1.0, 0.5, 0.2], diverged=["a"])).diverged  # the engine's flag
    assert not _summary(0, _task([1.0, 0.5, 0.2], diverged=[])).diverged


def test_a_diverged_configuration_is_never_the_best() -> None:
    frozen = _summary(0, _task([1.0, 0.1, 0.0], diverged=["a"]))  # zero weights after freezing: error looks low
    fine = _summary(1, _task([1.0, 0.5, 0.3]))
    mark_best([frozen, fine])
    assert (frozen.best, fine.best) == (False, True)
    assert summary_json(frozen)["diverged"] is True and summary_json(fine)["diverged"] is False


def test_the_csv_exports_flag_divergence_and_carry_the_learning_curves() -> None:
    summaries = [_summary(0, _task([1.0, 0.5, 0.2])), _summary(1, _task([1.0, 3e4, 2e9]))]
    results = list(csv.DictReader(io.StringIO(results_csv(summaries))))
    assert {(r["config"], r["demon"]): r["diverged"] for r in results} == {
        ("0", "*"): "0", ("0", "a"): "0", ("1", "*"): "1", ("1", "a"): "1"
    }  # fmt: skip
    curves = list(csv.DictReader(io.StringIO(curves_csv(summaries))))
    assert len(curves) == 2 * 2 * 3  # configurations x (all demons, a) x checkpoints
    for s in summaries:
        mine = [r for r in curves if r["config"] == str(s.index) and r["demon"] == "a"]
        assert [int(r["episode"]) for r in mine] == s.episodes
        assert [float(r["error"]) for r in mine] == s.demons["a"].curve.mean
        assert [float(r["ci_low"]) for r in mine] == s.demons["a"].curve.low
        assert {r["learning.alpha"] for r in mine} == {str(s.axes["learning.alpha"])}
        assert {r["diverged"] for r in mine} == {str(int(s.diverged))}


def _drawn(monkeypatch: pytest.MonkeyPatch, tmp_path: Path, summaries: list[ConfigSummary]) -> dict[str, Any]:
    """Each figure's y limits, title and legend, as write_plots draws them."""
    seen: dict[str, Any] = {}

    def keep(fig: Any, path: Path) -> None:
        ax = fig.axes[0]
        legend = ax.get_legend()
        texts = [t.get_text() for t in legend.get_texts()] if legend else []
        seen[path.name] = {"ylim": ax.get_ylim(), "title": ax.get_title(), "legend": texts}
        plots.plt.close(fig)

    monkeypatch.setattr(plots, "_save", keep)
    plots.write_plots(summaries, tmp_path)
    return seen


def test_the_plots_mark_a_diverged_configuration_and_leave_it_out_of_the_y_scale(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    fine = [_summary(i, _task([1.0, 0.5 / (i + 1), 0.2 / (i + 1)])) for i in range(2)]
    wild = _summary(2, _task([1.0, 3e4, 2e9]))
    drawn = _drawn(monkeypatch, tmp_path, [*fine, wild])
    for figure in ("learning-curves", "sensitivity-final", "sensitivity-auc"):
        high = drawn[figure]["ylim"][1]
        assert high < 10, (figure, drawn[figure])  # scaled to the curves that did not diverge, not to 2e9
        assert "diverged" in drawn[figure]["title"], drawn[figure]
        assert any("diverged" in text for text in drawn[figure]["legend"]), drawn[figure]
    calm = _drawn(monkeypatch, tmp_path, fine)
    assert all("diverged" not in calm[f]["title"] for f in calm)


def test_gtd_at_alpha_w_zero_is_warned_of_as_td() -> None:
    base = find_scenario("classroom-offpolicy")
    axes = [{"path": "demons.*.learner", "values": ["td", "gtd"]}, {"path": "learning.alpha_w", "values": [0.0, 1e-3]}]
    configurations = expand(StudySpec.model_validate({"base": base.model_dump(by_alias=True), "axes": axes}), base)
    warnings = study_warnings(configurations)
    gtd_at_zero = [c.index for c in configurations if c.axes == {"demons.*.learner": "gtd", "learning.alpha_w": 0.0}]
    assert len(warnings) == 1 and f"configuration {gtd_at_zero[0]};" in warnings[0], warnings
    assert "td and gtd give identical results" in warnings[0]
    assert study_warnings([c for c in configurations if c.axes["learning.alpha_w"] > 0]) == []
