"""Diverged demons: detected before their numbers stop meaning anything, reported as null on every route."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from horde.runs.divergence import MAX_MAGNITUDE, meaningful
from horde.server.settings import Settings

from .helpers import make_spec, wait_protocol

pytestmark = pytest.mark.filterwarnings("ignore::RuntimeWarning")  # the wild demons' error measures overflow

# Step sizes of 10 / 5 active features = 2 with lambda = 1: both learners blow up within a few steps.
WILD = [
    {"name": "gq_wild", "learner": "gq", "policy": "uniform", "cumulant": 1, "alpha": 10, "lambda": 1},
    {"name": "td_wild", "learner": "td", "policy": "uniform", "cumulant": 1, "alpha": 10, "lambda": 1},
]


@pytest.fixture
def settings(tmp_path: Path) -> Settings:
    """A history row at every step (none skipped for time: the steps before the divergence are recorded however
    fast the machine)."""
    return Settings(data=tmp_path / "data", token=None, snapshot_every=3600.0, history=2000, history_interval=0.0)


def test_meaningful_numbers() -> None:
    assert meaningful(1.5) == 1.5 and meaningful(-MAX_MAGNITUDE) == -MAX_MAGNITUDE
    assert meaningful(1.6e307) is None and meaningful(float("nan")) is None and meaningful(float("-inf")) is None


def test_a_diverged_gq_demon_is_reported_like_a_diverged_td_demon(
    client: TestClient, create_run: Callable[..., str]
) -> None:
    run = create_run(make_spec(demons=make_spec()["demons"] + WILD))
    state = client.post(f"/api/runs/{run}/step", json={"steps": 500}).json()
    for name in ("gq_wild", "td_wild"):
        assert state["metrics"][name]["diverged"] is True, state["metrics"][name]
        assert state["predictions"][name] is None
        demon = client.get(f"/api/runs/{run}/demons/{name}").json()
        assert demon["prediction"] is None and demon["metrics"]["diverged"] is True
        values = client.get(f"/api/runs/{run}/demons/{name}/values", params={"resolution": 4}).json()
        assert values["values"] == [[None] * 4] * 4 and values["min"] is None and values["max"] is None
        evaluation = client.post(f"/api/runs/{run}/evaluate", json={"demon": name, "from": [0, 0], "episodes": 3})
        assert evaluation.status_code == 200 and evaluation.json()["prediction"] is None
        history = client.get(f"/api/runs/{run}/demons/{name}/history").json()["prediction"]
        # numbers while it learned, null from its divergence on (its frozen prediction, 0, is no answer)
        first = next((i for i, v in enumerate(history) if v is None), None)
        assert first is not None, f"{name}: no null in its history after it diverged: {history[-3:]}"
        assert first > 0 and all(abs(v) <= MAX_MAGNITUDE for v in history[:first]), history[: first + 1]
        assert all(v is None for v in history[first:]), history[first:]
    assert state["metrics"]["steps"]["diverged"] is False and state["predictions"]["steps"] is not None
    events = [e["message"] for e in client.get(f"/api/runs/{run}/state").json()["events"] if e["kind"] == "error"]
    assert sorted(m.split("'")[1] for m in events if "diverged" in m) == ["gq_wild", "td_wild"], events


def test_a_protocol_reports_diverged_predictions_as_null(client: TestClient) -> None:
    spec = make_spec(episodes=20, demons=make_spec()["demons"] + WILD)
    job = wait_protocol(client, client.post("/api/protocols", json=spec).json()["id"])
    results = {r["name"]: r["prediction"] for r in job["results"]}
    assert results["gq_wild"] is None and results["td_wild"] is None and results["steps"] is not None, results
