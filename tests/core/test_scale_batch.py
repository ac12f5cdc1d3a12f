"""Trials run side by side (`batch.run_trials_batched`) return exactly what single trials return; by default
they take the process's share of the cores (`core/threads.py`), and a progress bar moves while they learn."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import pytest

from horde.cli import main
from horde.core import batch, threads
from horde.core.batch import default_workers, run_protocol_batched, run_trials_batched
from horde.core.experiment import run_protocol, run_trial
from horde.scenarios import load_scenario, scenario_dir
from horde.spec import RunSpec


def small_experiment1(trials: int, episodes: int = 40) -> RunSpec:
    spec = load_scenario(scenario_dir() / "experiment1.toml")
    data = spec.model_dump(by_alias=True)
    data["protocol"].update(trials=trials, episodes=episodes)
    data["protocol"]["evaluation"].update(rollouts=50, cap=500)
    return RunSpec.model_validate(data)


def test_batched_trials_equal_single_trials_with_the_same_seeds() -> None:
    spec = small_experiment1(3)
    batched = run_trials_batched(spec, workers=2)
    single = [run_trial(spec, trial) for trial in range(3)]
    assert [t.predictions for t in batched] == [t.predictions for t in single]
    assert [t.truths for t in batched] == [t.truths for t in single]
    assert [(t.episodes, t.steps) for t in batched] == [(t.episodes, t.steps) for t in single]
    assert len({t.predictions["steps_to_end"] for t in batched}) == 3, "each trial has its own seed"


def test_batched_protocol_equals_the_protocol() -> None:
    spec = small_experiment1(2)
    progress: list[tuple[int, int]] = []
    batched = run_protocol_batched(spec, workers=1, progress=lambda done, total: progress.append((done, total)))
    plain = run_protocol(spec)
    assert [d.as_dict() for d in batched.demons] == [d.as_dict() for d in plain.demons]
    assert batched.steps == plain.steps
    assert progress[-1] == (80, 80)


def test_horde_run_with_workers_prints_the_same_results(tmp_path: Path) -> None:
    scenario = str(scenario_dir() / "experiment1.toml")
    outputs = []
    for workers in ("1", "2"):
        out = tmp_path / f"workers{workers}.json"
        args = ["run", scenario, "--trials", "2", "--episodes", "20", "--quiet", "--json", str(out)]
        assert main([*args, "--workers", workers]) == 0
        outputs.append(json.loads(out.read_text()))
    assert outputs[0] == outputs[1]


@pytest.fixture
def budget() -> Iterator[None]:
    yield
    threads.set_budget(None)


def test_the_default_takes_the_process_share_of_the_cores(budget: None) -> None:
    threads.set_budget(2)
    assert default_workers(10) == 2, "alone, every core"
    assert default_workers(1) == 1, "never more processes than trials"
    with threads.running():
        assert default_workers(10) == 1, "with a run learning in the process, its share"
    threads.set_budget(1)
    assert default_workers(10) == 1


def test_one_core_runs_the_trials_in_this_process(budget: None, monkeypatch: pytest.MonkeyPatch) -> None:
    """With a budget of one core no pool is started, and the progress bar moves within each trial."""
    threads.set_budget(1)

    def no_pool(*args: object, **kwargs: object) -> None:
        raise AssertionError("a process pool was started on one core")

    monkeypatch.setattr(batch, "ProcessPoolExecutor", no_pool)
    spec = small_experiment1(2, episodes=250)  # the trial reports every 100 episodes (one call of the loop)
    reports: list[tuple[int, int]] = []
    results = run_trials_batched(spec, progress=lambda done, total: reports.append((done, total)))
    assert [t.steps for t in results] == [run_trial(spec, trial).steps for trial in range(2)]
    done = [d for d, _ in reports]
    assert done == sorted(done) and reports[-1] == (500, 500)
    assert {100, 200, 350, 450} <= set(done), f"no reports within the trials: {reports}"


def test_workers_report_their_episodes_as_they_learn(monkeypatch: pytest.MonkeyPatch) -> None:
    """Two workers, one trial each: the parent hears of episodes before a trial ends, never going back."""
    monkeypatch.setattr(batch, "POLL_SECONDS", 0.01)
    spec = small_experiment1(2, episodes=2000)
    reports: list[int] = []
    results = run_trials_batched(spec, workers=2, progress=lambda done, total: reports.append(done))
    assert [t.episodes for t in results] == [2000, 2000]
    assert reports == sorted(reports) and reports[-1] == 4000
    assert len(set(reports)) > 2, f"only the trials' ends were reported: {reports}"


def test_horde_run_by_default_prints_what_one_worker_prints(tmp_path: Path) -> None:
    scenario = str(scenario_dir() / "experiment1.toml")
    outputs = []
    for workers in ([], ["--workers", "1"]):
        out = tmp_path / f"run{len(outputs)}.json"
        args = ["run", scenario, "--trials", "3", "--episodes", "20", "--quiet", "--json", str(out)]
        assert main([*args, *workers]) == 0
        outputs.append(json.loads(out.read_text()))
    assert outputs[0] == outputs[1]
