"""GET /api/overview (the Class tab): every run as a card naming its owner, with a sparkline of its first demons'
predictions read from the history the run's worker published (the API process holds no learner)."""

from __future__ import annotations

from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from horde.server import Settings
from horde.server.routes.overview import SPARK_POINTS
from polling import wait_until

from .helpers import make_spec
from .test_roles import TEACHER, bearer, issue, new_run


@pytest.fixture
def settings(tmp_path: Path) -> Settings:
    return Settings(data=tmp_path / "data", token="s3cret", snapshot_every=3600.0)


def test_overview_cards_name_the_owner_and_thin_the_published_history(client: TestClient) -> None:
    student = issue(client, "student", "ada")
    mine, theirs = new_run(client, bearer(student["token"])), new_run(client, TEACHER)
    ada = bearer(student["token"])
    assert client.patch(f"/api/runs/{mine}", json={"hz": 200}, headers=ada).status_code == 200  # a row a step
    assert client.post(f"/api/runs/{mine}/start", headers=ada).status_code == 200
    wait_until(lambda: client.get(f"/api/runs/{mine}").json()["step"] >= 2 * SPARK_POINTS or None, "steps", 60.0)
    steps = client.post(f"/api/runs/{mine}/pause", headers=ada).json()["step"]

    cards = client.get("/api/overview").json()  # reading needs no token
    assert [(c["id"], c["owner"]) for c in cards] == [(mine, "ada"), (theirs, "teacher")]
    card = cards[0]
    assert card["step"] == steps
    names = [d["name"] for d in make_spec()["demons"]]
    assert list(card["sparkline"]["series"]) == names  # the first demons, in the run's order
    history = client.get(f"/api/runs/{mine}/demons/{names[0]}/history").json()
    spark_steps = card["sparkline"]["steps"]
    assert len(history["step"]) > SPARK_POINTS
    assert len(spark_steps) == SPARK_POINTS  # thinned, from the oldest row to the newest
    assert spark_steps[0] == history["step"][0] and spark_steps[-1] == history["step"][-1]
    at = {s: p for s, p in zip(history["step"], history["prediction"], strict=True)}
    assert card["sparkline"]["series"][names[0]] == [at[s] for s in spark_steps]
    assert cards[1]["step"] == 0 and cards[1]["sparkline"]["steps"] == []
