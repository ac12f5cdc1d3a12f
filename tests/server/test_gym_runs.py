"""Gymnasium worlds as live runs over REST: created, stepped, paused, with demons, history and snapshots."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

from horde.server import Settings, create_app
from horde.spec import RunSpec
from horde.worlds.gymnasium import GymAgent
from polling import wait_until

from .helpers import wait_for

# MountainCar with four demons: position and velocity at two timescales, under the energy-pumping behaviour.
SENSOR_FEATURES = {
    "kind": "sensors",
    "tilings": 4,
    "tiles": 6,
    "size": 512,
    "sensors": [{"sensor": "position", "low": -1.2, "high": 0.6}, {"sensor": "velocity", "low": -0.07, "high": 0.07}],
}
PUMP = {"kind": "sign", "sensor": "velocity", "actions": [0, 2], "epsilon": 0.5}


def gym_spec(**changes: Any) -> dict[str, Any]:
    spec: dict[str, Any] = {
        "name": "car",
        "seed": 5,
        "world": {"kind": "gymnasium", "id": "MountainCar-v0"},
        "features": SENSOR_FEATURES,
        "behaviour": PUMP,
        "demons": [
            {"name": f"{s}_g{g}", "learner": "td", "policy": PUMP, "cumulant": {"sensor": s}, "discount": g}
            for s in ("position", "velocity")
            for g in (0.5, 0.9)
        ],
        "protocol": {"episodes": 0},
    }
    spec.update(changes)
    return spec


def test_a_gymnasium_run_steps_learns_and_equals_the_agent_of_horde_run(client: TestClient) -> None:
    created = client.post("/api/runs", json=gym_spec())
    assert created.status_code == 201, created.text
    run = created.json()["id"]
    stepped = client.post(f"/api/runs/{run}/step", json={"steps": 300}).json()
    assert stepped["status"] == "paused" and stepped["step"] == 300
    # The same spec, seeded as trial 0 of its protocol, stepped by the agent that `horde run` uses.
    agent = GymAgent(RunSpec.model_validate(gym_spec()), np.random.default_rng([5, 0]))
    agent.run(300)
    state = client.get(f"/api/runs/{run}/state").json()
    assert state["predictions"] == agent.predictions()
    assert state["episode"] == agent.episode
    assert state["sensors"]["position"] == agent.sensors[0] and state["agent"]["x"] == agent.sensors[0]
    demons = client.get(f"/api/runs/{run}/demons").json()
    assert [d["name"] for d in demons] == list(agent.predictions())
    assert all(d["metrics"]["rupee"] is not None for d in demons)
    history = client.get(f"/api/runs/{run}/demons/position_g0.5/history").json()
    assert 0 < history["step"][-1] <= 300 and len(history["prediction"]) == len(history["step"]) >= 2


def test_a_gymnasium_run_runs_pauses_and_takes_demons(client: TestClient) -> None:
    run = client.post("/api/runs", json=gym_spec(), params={"start": "true", "hz": 200}).json()["id"]
    wait_for(client, run, "running")
    wait_until(lambda: client.get(f"/api/runs/{run}").json()["step"] >= 20, "20 steps at 200 steps/s", 30.0)
    client.post(f"/api/runs/{run}/pause")
    paused = client.get(f"/api/runs/{run}/state").json()
    assert paused["status"] == "paused" and paused["step"] > 0
    joined = client.post(f"/api/runs/{run}/demons", json={"name": "goal", "outcome": {"sensor": "terminated"},
                                                          "discount": 0.9, "learner": "td"})  # fmt: skip
    assert joined.status_code in (200, 201), joined.text
    state = client.get(f"/api/runs/{run}/state").json()
    assert "goal" in state["predictions"] and state["step"] == paused["step"]
    for name in ("position_g0.5", "velocity_g0.9"):  # demons that stayed kept their weights (read afresh)
        assert state["predictions"][name] == pytest.approx(paused["predictions"][name], rel=1e-12)


def test_a_value_map_or_evaluation_from_a_point_is_a_422_naming_why(client: TestClient) -> None:
    run = client.post("/api/runs", json=gym_spec()).json()["id"]
    values = client.get(f"/api/runs/{run}/demons/position_g0.5/values")
    assert values.status_code == 422 and "grid world" in values.text
    evaluation = client.post(f"/api/runs/{run}/evaluate", json={"demon": "position_g0.5", "from": [0, 0]})
    assert evaluation.status_code == 422 and evaluation.json()["detail"][0]["loc"][-1] == "from"


@pytest.mark.timeout(120)
def test_a_gymnasium_run_is_evaluated_by_rollouts_from_the_agents_current_state(client: TestClient) -> None:
    created = client.post("/api/runs", json={"scenario": "mountaincar-nexting"})
    assert created.json()["evaluation"]["kind"] == "rollouts", created.json()["evaluation"]
    run = created.json()["id"]
    client.post(f"/api/runs/{run}/step", json={"steps": 400})
    state = client.get(f"/api/runs/{run}/state").json()
    request = {"demon": "position_g0.5_on", "episodes": 30, "seed": 1}
    response = client.post(f"/api/runs/{run}/evaluate", json=request)
    assert response.status_code == 200, response.text
    body = response.json()
    assert body["from"] == list(state["sensors"].values()) and body["exact"] is None
    assert body["prediction"] == state["predictions"]["position_g0.5_on"]
    assert body["stderr"] is not None and body["stderr"] >= 0 and body["error"] == body["prediction"] - body["truth"]
    # The discounted position at gamma 0.5 weighs the next few positions: (1 - gamma) G lies near where the car
    # is now (it moves at most 0.07 a step), not where a fresh episode starts.
    assert abs(0.5 * body["truth"] - state["sensors"]["position"]) < 0.15, (body["truth"], state["sensors"])
    assert client.post(f"/api/runs/{run}/evaluate", json=request).json() == body  # seeded: repeatable
    assert client.get(f"/api/runs/{run}/state").json()["step"] == 400  # the run did not move


def test_a_question_that_rollouts_cannot_follow_is_a_422_naming_the_demon(client: TestClient) -> None:
    reader = {"name": "reader", "learner": "td", "cumulant": {"prediction": "position_g0.5"}, "discount": 0.5}
    run = client.post("/api/runs", json=gym_spec(demons=[*gym_spec()["demons"], reader])).json()["id"]
    response = client.post(f"/api/runs/{run}/evaluate", json={"demon": "reader", "episodes": 3})
    assert response.status_code == 422 and response.json()["detail"][0]["loc"] == ["body", "demon"], response.text
    assert "reads other demons" in response.text
    too_many = client.post(f"/api/runs/{run}/evaluate", json={"demon": "position_g0.5", "episodes": 5000, "cap": 1000})
    assert too_many.status_code == 422 and too_many.json()["detail"][0]["loc"] == ["body", "episodes"], too_many.text


def test_an_unknown_environment_or_unsupported_space_is_a_422_naming_world_id(client: TestClient) -> None:
    for env_id in ("NoSuchEnv-v0", "Pendulum-v1"):  # not installed; a Box action space
        response = client.post("/api/runs", json=gym_spec(world={"kind": "gymnasium", "id": env_id}))
        assert response.status_code == 422, response.text
        assert response.json()["detail"][0]["loc"][-2:] == ["world", "id"], response.json()
    stream_world = {"kind": "stream", "sensors": [{"name": "a"}], "actions": 2}
    body = gym_spec(world=stream_world, features={"kind": "constant"}, behaviour="uniform", demons=[{"name": "a"}])
    stream = client.post("/api/runs", json=body)
    assert stream.status_code == 422 and "POST /api/streams" in stream.text


def test_a_gymnasium_run_comes_back_after_a_restart_exactly_where_it_stood(tmp_path: Path) -> None:
    settings = Settings(data=tmp_path / "data", token=None, snapshot_every=3600.0, history=2000, max_runs=8)
    with TestClient(create_app(settings)) as client:
        run = client.post("/api/runs", json=gym_spec()).json()["id"]
        client.post(f"/api/runs/{run}/step", json={"steps": 250})
        twin = client.post("/api/runs/import", json=client.get(f"/api/runs/{run}/snapshot").json()).json()["id"]
        before = client.get(f"/api/runs/{run}/state").json()
    with TestClient(create_app(settings)) as client:
        after = client.get(f"/api/runs/{run}/state").json()
        assert after["predictions"] == before["predictions"] and after["sensors"] == before["sensors"]
        resumed = client.post(f"/api/runs/{run}/step", json={"steps": 400}).json()
        reference = client.post(f"/api/runs/{twin}/step", json={"steps": 400}).json()
        assert resumed["step"] == 650 and resumed["predictions"] == reference["predictions"]
        assert (
            client.get(f"/api/runs/{run}/state").json()["sensors"]
            == client.get(f"/api/runs/{twin}/state").json()["sensors"]
        )
