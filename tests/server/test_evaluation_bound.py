"""A long evaluation is bounded in time and ends with its client (issue 24, item 8).

5,000 rollouts of 10,000 steps took 95 s and went on after the client had gone, holding one of the two
evaluation slots and a request thread all the while. The rollouts now run in chunks of at most
`CHUNK_STEPS` steps and are given up once HORDE_EVALUATION_SECONDS have passed (a 422 at `episodes`), or
at the first chunk after the client hangs up, so an evaluation holds its slot no longer than someone waits
for it, and never past the budget.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator

import httpx
import numpy as np
import pytest
from fastapi.testclient import TestClient

from grids import WALL, grid
from horde.core.evaluate import StoppedError, monte_carlo
from horde.runs.run_setup import new_simulation
from horde.server import Settings, create_app
from horde.spec import RunSpec
from polling import wait_until
from serving import serve_in_thread

from .helpers import assert_healthy, locs, make_spec

BUDGET = 1.0  # seconds: HORDE_EVALUATION_SECONDS of these tests
HANG_UP_BOUND = 5.0  # seconds from a hang-up to its evaluation's slot free again
# A question that never ends (no terminal, continuation 1): every rollout runs to its cap.
FOREVER = {
    "name": "forever",
    "world": grid(WALL),
    "behaviour": "uniform",
    "demons": [{"name": "forever", "learner": "td", "policy": "uniform", "cumulant": 1}],
}
LONG = {"demon": "forever", "from": [0, 0], "episodes": 5000, "cap": 10000}  # 5 x 10^7 steps: 12 s alone, quiet


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


@pytest.mark.timeout(180)
def test_an_evaluation_whose_client_hangs_up_frees_its_slot(settings: Settings) -> None:
    """Both slots taken by 5 x 10^7-step evaluations whose clients give up after a second: a third is refused
    (429) while they run, and answered within HANG_UP_BOUND of the hang-ups (the route checks every 0.25 s,
    a chunk of rollouts takes about 0.05 s), long before the budget (300 s) or the rollouts (12 s alone on a
    quiet machine, two at once longer) would end them."""
    with serve_in_thread(settings.model_copy(update={"evaluation_seconds": 300.0})) as server:
        client = server.client
        run_id = client.post("/api/runs", json=FOREVER).json()["id"]
        path = f"/api/runs/{run_id}/evaluate"
        short = {**LONG, "episodes": 3, "cap": 100}
        assert client.post(path, json=short).status_code == 200  # compiles the rollouts (once per process)

        gave_up: list[bool] = []

        def give_up_after_a_second() -> None:
            with httpx.Client(base_url=server.url, timeout=1.0) as impatient:
                for _ in range(200):  # a slot held for a moment by the polling below is tried again (a 429 at once)
                    try:
                        if impatient.post(path, json=LONG).status_code != 429:
                            return
                    except httpx.ReadTimeout:
                        gave_up.append(True)
                        return

        quitters = [threading.Thread(target=give_up_after_a_second) for _ in range(2)]
        for quitter in quitters:
            quitter.start()
        wait_until(lambda: client.post(path, json=short).status_code == 429, "both slots to be taken", timeout=30)
        for quitter in quitters:
            quitter.join(timeout=30)
        assert gave_up == [True, True]  # both were still rolling out when their clients hung up
        hung_up = time.monotonic()
        wait_until(lambda: client.post(path, json=short).status_code == 200, "a slot freed by a hang-up",
                   timeout=HANG_UP_BOUND)  # fmt: skip
        print(f"a slot was free {time.monotonic() - hung_up:.2f} s after the clients hung up")
        assert_healthy(client)
