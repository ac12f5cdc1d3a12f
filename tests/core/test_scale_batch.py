"""Trials run side by side (`batch.run_trials_batched`) return exactly what single trials return."""

from __future__ import annotations

import json
from pathlib import Path

from horde.cli import main
from horde.core.batch import run_protocol_batched, run_trials_batched
from horde.core.experiment import run_protocol, run_trial
from horde.scenarios import load_scenario, scenario_dir
from horde.spec import RunSpec


def small_experiment1(trials: int) -> RunSpec:
    spec = load_scenario(scenario_dir() / "experiment1.toml")
    data = spec.model_dump(by_alias=True)
    data["protocol"].update(trials=trials, episodes=40)
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
