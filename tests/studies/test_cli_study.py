"""`horde study`: a table, JSON per configuration, plots, and bad axes reported with file and line."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from horde.cli import main
from horde.studies.files import load_study_file, study_dir

from .helpers import alpha_by_learner

STUDY = alpha_by_learner(runs=3, episodes=40, checkpoints=2, learners=("td", "gtd"), name="tiny")


def test_study_prints_a_table_and_writes_json_and_plots(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "tiny.toml"
    path.write_text(STUDY)
    out, plots = tmp_path / "out.json", tmp_path / "plots"
    code = main(
        ["study", str(path), "--local", "--data", str(tmp_path / "d"), "--json", str(out), "--plots", str(plots)]
    )
    assert code == 0
    captured = capsys.readouterr()
    assert "12/12 tasks" in captured.err and "left" in captured.err  # the progress bar: counts and time left
    assert "alpha=0.1 learner='gtd'" in captured.out and "95% CI" in captured.out
    rows = json.loads(out.read_text())
    assert len(rows) == 4 and sum(r["best"] for r in rows) == 1
    for row in rows:
        assert set(row) >= {"axes", "runs", "error", "ci_low", "ci_high", "demons"}
        assert row["runs"] == 3 and row["ci_low"] <= row["error"] <= row["ci_high"]
        assert set(row["demons"]) == {"steps_northeast", "goal_northeast", "steps_southwest", "goal_southwest",
                                      "steps_random", "goal_random"}  # fmt: skip
        for demon in row["demons"].values():
            assert demon["ci_low"] <= demon["error"] <= demon["ci_high"]
    for stem in ("learning-curves", "sensitivity-final", "sensitivity-auc"):
        for suffix in (".png", ".svg"):
            assert (plots / f"{stem}{suffix}").stat().st_size > 5000


def test_study_warns_of_gtd_as_td_and_writes_results_and_curves_csv(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "zero.toml"
    study = alpha_by_learner(runs=1, episodes=10, checkpoints=2, learners=("td", "gtd"), name="zero")
    path.write_text(study + '\n[[axes]]\npath = "learning.alpha_w"\nvalues = [0.0]\n')
    folder = tmp_path / "csv"
    assert main(["study", str(path), "--local", "--quiet", "--data", str(tmp_path / "d"), "--csv", str(folder)]) == 0
    assert "warning: gtd with alpha_w = 0 learns exactly as td" in capsys.readouterr().err
    results = list(csv.DictReader((folder / "results.csv").open()))
    curves = list(csv.DictReader((folder / "curves.csv").open()))
    assert len(results) == 4 * 7 and {r["diverged"] for r in results} == {"0"}
    assert len(curves) == 4 * 7 * 3  # configurations x (all demons, six demons) x checkpoints 0, 5, 10
    assert sorted({int(r["episode"]) for r in curves}) == [0, 5, 10]


@pytest.mark.parametrize(
    ("replace", "by", "expected"),
    [
        ('path = "learning.alpha"', 'path = "learning.alfa"', ":10: axes.0.path: axis learning.alfa: unknown path"),
        ('values = ["td", "gtd"]', 'values = ["td", "sarsa"]', ":15: axes.1.values.1: axis demons.*.learner = 'sarsa'"),
        ("values = [0.03, 0.1]", "values = [0.03, -1]", ":11: axes.0.values.1: axis learning.alpha = -1"),
        ("runs = 3", "runs = 0", ":3: runs: Input should be greater than or equal to 1"),
    ],
)
def test_a_bad_axis_is_reported_with_file_and_line_before_any_task(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], replace: str, by: str, expected: str
) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(STUDY.replace(replace, by))
    data = tmp_path / "d"
    assert main(["study", str(path), "--local", "--data", str(data)]) == 2
    err = capsys.readouterr().err
    assert f"{path}{expected}" in err
    assert "tasks" not in err  # no task started


def test_a_grid_past_the_bound_is_reported_at_the_axes(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    values = ", ".join(str(0.001 * (i + 1)) for i in range(40))
    path = tmp_path / "big.toml"
    path.write_text(
        f'scenario = "experiment1"\n[[axes]]\npath = "learning.alpha"\nvalues = [{values}]\n'
        f'[[axes]]\npath = "learning.alpha_w"\nvalues = [{values}]\n'
    )
    assert main(["study", str(path), "--local", "--data", str(tmp_path / "d")]) == 2
    assert "1600 configurations, more than 1000" in capsys.readouterr().err


def test_resume_of_an_unknown_study_is_an_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["study", "--resume", "nope", "--local", "--data", str(tmp_path)]) == 2
    assert "no study 'nope'" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["stepsizes", "experiment1-seeds"])
def test_the_shipped_studies_validate(name: str) -> None:
    study, _base, configurations = load_study_file(study_dir() / f"{name}.toml")
    assert configurations and study.runs >= 5
