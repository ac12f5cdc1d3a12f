"""Small specs and the waits of the server tests (runs, protocol jobs, studies), on `polling.wait_until`.

The waits take any client with `get` (FastAPI's TestClient in process, httpx against a real server).
"""

from __future__ import annotations

import statistics
import time
from typing import Any

from grids import GOAL, PIT, WALL, grid
from polling import wait_until

# A small thesis-like world: softmax control demon `base` and a prediction demon `steps` following it.
WORLD: dict[str, Any] = grid(GOAL, PIT, WALL)
BASE_DEMON: dict[str, Any] = {
    "name": "base",
    "policy": "softmax",
    "cumulant": -0.01,
    "outcome": {
        "if": {"sensor": "in:goal"},
        "then": 1,
        "else": {"if": {"sensor": "in:pit"}, "then": -1, "else": 0},
    },
}
STEPS_DEMON: dict[str, Any] = {"name": "steps", "policy": {"of": "base"}, "cumulant": 1, "alpha": 0.05}


def make_spec(episodes: int = 0, **changes: Any) -> dict[str, Any]:
    """A RunSpec body: the world above, base + steps demons, softmax behaviour over base."""
    spec: dict[str, Any] = {
        "name": "small",
        "seed": 3,
        "world": WORLD,
        "behaviour": {"kind": "softmax", "demon": "base"},
        "demons": [BASE_DEMON, STEPS_DEMON],
        "protocol": {"episodes": episodes, "evaluation": {"rollouts": 0}},
    }
    spec.update(changes)
    return spec


def _until_status(client: Any, path: str, status: str, what: str, timeout: float) -> dict[str, Any]:
    def reached() -> dict[str, Any]:
        body: dict[str, Any] = client.get(path).json()
        assert body["status"] == status, f"{body['status']}: {body.get('message') or body.get('error')}"
        return body

    return wait_until(reached, f"{what} to be {status}", timeout)


def wait_for(client: Any, run_id: str, status: str, timeout: float = 30.0) -> dict[str, Any]:
    """Poll GET /api/runs/{id} until the run has `status`; return its body."""
    return _until_status(client, f"/api/runs/{run_id}", status, f"run {run_id}", timeout)


def wait_protocol(client: Any, job_id: str, timeout: float = 60.0) -> dict[str, Any]:
    """Poll GET /api/protocols/{id} until the job no longer runs; return its body (finished or not)."""

    def stopped() -> dict[str, Any]:
        job: dict[str, Any] = client.get(f"/api/protocols/{job_id}").json()
        assert job["status"] != "running", f"running, {job['episodes_done']} of {job['episodes_total']} episodes"
        return job

    return wait_until(stopped, f"protocol job {job_id} to stop", timeout)


def wait_study(client: Any, study_id: str, status: str, timeout: float = 60.0) -> dict[str, Any]:
    """Poll GET /api/studies/{id} until the study has `status`; return its body."""
    return _until_status(client, f"/api/studies/{study_id}", status, f"study {study_id}", timeout)


def locs(response: Any) -> list[list[Any]]:
    """The `loc` of every problem in a 422 body."""
    assert response.status_code == 422, response.text
    return [problem["loc"] for problem in response.json()["detail"]]


def messages(response: Any) -> str:
    assert response.status_code == 422, response.text
    return " | ".join(problem["msg"] for problem in response.json()["detail"])


HEALTH_MEDIAN = 0.1  # seconds: the median /api/health answer after a reproducer (issue 24)
HEALTH_STALL = 1.0  # seconds: no answer may take longer


def assert_healthy(client: Any, checks: int = 5) -> None:
    """/api/health answers 200, the median of `checks` answers within HEALTH_MEDIAN and none beyond HEALTH_STALL:
    the server is alive and its loop not stalled (a median, as test_health_under_attack, on a shared machine)."""
    times = []
    for _ in range(checks):
        start = time.perf_counter()
        response = client.get("/api/health")
        times.append(time.perf_counter() - start)
        assert response.status_code == 200, response.text
    assert statistics.median(times) <= HEALTH_MEDIAN and max(times) <= HEALTH_STALL, times
