"""A long evaluation is bounded in time (issue 24, item 8).

5,000 rollouts of 10,000 steps took 95 s and went on after the client had gone, holding one of the two
evaluation slots and a request thread all the while. The rollouts now run in chunks of at most
`CHUNK_STEPS` steps and are given up once HORDE_EVALUATION_SECONDS have passed (a 422 at `episodes`), so
an evaluation holds its slot that long at most whether or not its client still waits. (Cancelling on a
disconnect instead would need the request's connection in the worker thread that runs the route.)
"""

from __future__ import annotations

import time
from collections.abc import Iterator

import numpy as np
import pytest
from fastapi.testclient import TestClient

from grids import WALL, grid
from horde.core.evaluate import StoppedError, monte_carlo
from horde.runs.run_setup import new_simulation
from horde.server import Settings, create_app
from horde.spec import RunSpec

from .helpers import assert_healthy, locs, make_spec

BUDGET = 1.0  # seconds: HORDE_EVALUATION_SECONDS of these tests
# A question that never ends (no terminal, continuation 1): every rollout runs to its cap.
FOREVER = {
    "name": "forever",
    "world": grid(WALL),
    "behaviour": "uniform",
    "demons": [{"name": "forever", "learner": "td", "policy": "uniform", "cumulant": 1}],
}
LONG = {"demon": "forever", "from": [0, 0], "episodes": 5000, "cap": 10000}  # 5 x 10^7 steps: over 90 s


@pytest.fixture
def bounded(settings: Settings) -> Iterator[TestClient]:
    with TestClient(create_app(settings.model_copy(update={"evaluation_seconds": BUDGET}))) as client:
        yield client


def test_a_5000_by_10000_evaluation_is_given_up_after_the_budget(bounded: TestClient) -> None:
    client = bounded
    run_id = client.post("/api/runs", json=FOREVER).json()["id"]
    path = f"/api/runs/{run_id}/evaluate"
    short = {**LONG, "episodes": 3, "cap": 100}
    assert client.post(path, json=short).status_code == 200  # compiles the rollouts (once per process)
    began = time.monotonic()
    response = client.post(path, json=LONG)
    took = time.monotonic() - began
    assert ["body", "episodes"] in locs(response)
    assert f"within {BUDGET:g} s" in response.json()["detail"][0]["msg"]
    assert took < BUDGET + 10, took  # the budget and a chunk or two past it, on a loaded machine
    for _ in range(3):  # the slot was freed (two evaluations at most run at once)
        assert client.post(path, json=short).status_code == 200
    assert_healthy(client)
    print(f"5,000 x 10,000 evaluation answered 422 after {took:.2f} s (budget {BUDGET:g} s)")


def test_chunked_rollouts_draw_the_same_numbers() -> None:
    spec = RunSpec.model_validate(make_spec())
    sim = new_simulation(spec)
    sim.run(500)
    whole = monte_carlo(sim.horde, sim.horde_state, "steps", (0.0, 0.0), 300, 10_000, np.random.default_rng(5))
    asked = []
    chunked = monte_carlo(sim.horde, sim.horde_state, "steps", (0.0, 0.0), 300, 10_000, np.random.default_rng(5),
                          stop=lambda: asked.append(1) is not None)  # fmt: skip
    assert chunked == whole and len(asked) > 1  # asked between chunks, never told to stop
    with pytest.raises(StoppedError):
        monte_carlo(sim.horde, sim.horde_state, "steps", (0.0, 0.0), 300, 10_000, np.random.default_rng(5),
                    stop=lambda: True)  # fmt: skip
