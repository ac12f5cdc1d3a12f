"""The `horde` command line: scenarios listing, protocol runs with a table and JSON, clear errors."""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest

from horde.cli import main
from horde.progress import ProgressBar
from horde.scenarios import scenario_dir


def test_scenarios_lists_each_with_a_description(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["scenarios"]) == 0
    lines = capsys.readouterr().out.splitlines()
    names = {line.split()[0] for line in lines}
    assert {"experiment1", "experiment3", "experiment2-large"} <= names
    assert all(len(line.split(maxsplit=1)) == 2 for line in lines)


def test_run_prints_the_table_and_writes_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "results.json"
    code = main(
        ["run", str(scenario_dir() / "experiment1.toml"), "--trials", "1", "--episodes", "20", "--json", str(out)]
    )
    assert code == 0
    captured = capsys.readouterr()
    assert "steps_to_end" in captured.out and "thesis" in captured.out
    assert "30.700" in captured.out
    assert "episodes" in captured.err  # the progress bar
    rows = json.loads(out.read_text())
    assert [r["name"] for r in rows] == ["base", "steps_to_end"]
    steps = rows[1]
    assert set(steps) == {"name", "prediction", "truth", "truth_stderr", "error", "thesis"}
    assert steps["thesis"] == 30.7
    assert steps["error"] == pytest.approx(steps["prediction"] - steps["truth"])
    assert steps["truth"] > 0 and steps["truth_stderr"] > 0


def test_control_protocol_reports_counts(tmp_path: Path) -> None:
    out = tmp_path / "results.json"
    code = main(
        ["run", str(scenario_dir() / "experiment3.toml"), "--trials", "1", "--episodes", "5", "--json", str(out),
         "--quiet"]
    )  # fmt: skip
    assert code == 0
    rows = {r["name"]: r for r in json.loads(out.read_text())}
    counts = rows["base"]["counts"]
    assert set(counts) == {"positive", "negative", "none"}
    assert sum(counts.values()) == 10  # 1 trial x 10 test runs
    assert rows["colour"]["thesis"] is None


def test_bad_scenario_is_a_clear_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text("[protocol]\ntrials = 0\n")
    assert main(["run", str(bad)]) == 2
    err = capsys.readouterr().err
    assert f"{bad}:2: protocol.trials" in err
    assert "Traceback" not in err


def test_bad_override_is_a_clear_error(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", str(scenario_dir() / "experiment1.toml"), "--trials", "0"]) == 2
    assert "trials" in capsys.readouterr().err


def test_negative_workers_is_a_clear_error(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", str(scenario_dir() / "experiment1.toml"), "--workers", "-2"]) == 2
    err = capsys.readouterr().err
    assert "--workers" in err and "Traceback" not in err


def test_the_progress_bar_draws_its_end_once() -> None:
    """The trials report their last episode and then their end: one finished bar, one line break."""
    stream = io.StringIO()
    bar = ProgressBar("x", stream=stream)
    for done in (0, 50, 100, 100):
        bar(done, 100)
    text = stream.getvalue()
    assert text.count("100/100") == 1 and text.count("\n") == 1, text
