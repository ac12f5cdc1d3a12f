"""Experiment 1 through REST alone gives the prediction that `horde.core.experiment.run_trial` gives."""

from __future__ import annotations

from fastapi.testclient import TestClient

from horde.core.experiment import run_trial
from horde.spec import RunSpec

from .helpers import wait_for


def test_experiment1_over_rest_equals_run_trial(client: TestClient) -> None:
    overrides = {"protocol": {"episodes": 40, "trials": 1, "evaluation": {"rollouts": 0}}}
    created = client.post("/api/runs", json={"scenario": "experiment1", **overrides}, params={"start": "true"})
    assert created.status_code == 201, created.text
    run_id = created.json()["id"]
    finished = wait_for(client, run_id, "finished", timeout=60)

    spec = RunSpec.model_validate(finished["spec"])
    trial = run_trial(spec, 0)
    assert finished["summary"]["predictions"] == trial.predictions  # bit for bit
    assert finished["summary"]["steps"] == trial.steps and finished["summary"]["episodes"] == trial.episodes

    start = spec.world.start[:2]
    evaluation = client.post(
        f"/api/runs/{run_id}/evaluate",
        json={"demon": "steps_to_end", "from": start, "episodes": 100, "cap": 2000, "seed": 5},
    ).json()
    assert evaluation["prediction"] == trial.predictions["steps_to_end"]
    assert evaluation["truth"] > 0 and evaluation["stderr"] < evaluation["truth"]
