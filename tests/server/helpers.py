"""Small specs and polling helpers shared by the server tests."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from fastapi.testclient import TestClient

# A small thesis-like world: softmax control demon `base` and a prediction demon `steps` following it.
WORLD: dict[str, Any] = {
    "width": 500,
    "height": 500,
    "step": 100,
    "start": [0, 0],
    "max_steps": 100,
    "regions": [
        {"name": "goal", "kind": "terminal", "rect": [400, 400, 500, 500], "reward": 1},
        {"name": "pit", "kind": "terminal", "rect": [400, 200, 500, 300], "reward": -1},
        {"name": "wall", "kind": "obstacle", "rect": [100, 200, 200, 300]},
    ],
}
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


def wait_for(client: TestClient, run_id: str, status: str, timeout: float = 30.0) -> dict[str, Any]:
    """Poll GET /api/runs/{id} until the run has `status`; return its body."""
    deadline = time.monotonic() + timeout
    while True:
        body: dict[str, Any] = client.get(f"/api/runs/{run_id}").json()
        if body["status"] == status:
            return body
        if time.monotonic() > deadline:
            raise AssertionError(f"run {run_id} is {body['status']}, not {status}: {body['message']}")
        time.sleep(0.02)


def locs(response: Any) -> list[list[Any]]:
    """The `loc` of every problem in a 422 body."""
    assert response.status_code == 422, response.text
    return [problem["loc"] for problem in response.json()["detail"]]


def messages(response: Any) -> str:
    assert response.status_code == 422, response.text
    return " | ".join(problem["msg"] for problem in response.json()["detail"])
