"""Evaluations are kept with their run: listed again after a restart, the latest per demon, dropped by a reset
and gone with the run."""

from __future__ import annotations

from fastapi.testclient import TestClient

from horde.server import Settings, create_app

from .helpers import make_spec

REQUEST = {"demon": "steps", "from": [0, 0], "episodes": 20, "cap": 2000, "seed": 1}


def test_an_evaluation_is_kept_with_its_run_across_a_restart(settings: Settings) -> None:
    with TestClient(create_app(settings)) as client:
        run_id = client.post("/api/runs", json=make_spec()).json()["id"]
        assert client.get(f"/api/runs/{run_id}/evaluations").json() == []
        client.post(f"/api/runs/{run_id}/step", json={"steps": 500})
        first = client.post(f"/api/runs/{run_id}/evaluate", json=REQUEST).json()
        again = client.post(f"/api/runs/{run_id}/evaluate", json={**REQUEST, "from": [100, 0]}).json()
        assert again["from"] != first["from"]
    with TestClient(create_app(settings)) as client:  # the server restarted
        assert client.get(f"/api/runs/{run_id}/evaluations").json() == [again], "the latest of the demon, kept"
        client.post(f"/api/runs/{run_id}/reset")
        assert client.get(f"/api/runs/{run_id}/evaluations").json() == [], "a reset drops the old truths"
        client.post(f"/api/runs/{run_id}/evaluate", json=REQUEST)
        assert client.delete(f"/api/runs/{run_id}").status_code == 204
        assert client.get(f"/api/runs/{run_id}/evaluations").status_code == 404
