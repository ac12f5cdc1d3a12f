"""What the store holds is untrusted at start-up too (issue 24, item 1): a row that no longer reads (a spec an
older version wrote, a row changed by hand) is left out, logged, and never stops a restart or makes a 500.

Before, a stored run whose spec did not read (with no snapshot, or one that did not read either) and a
protocol job whose spec or result did not read stopped the server's start ("Application startup failed");
a world or a study whose row did not read made every GET of the list a 500.
"""

from __future__ import annotations

import shutil
import sqlite3
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

from horde.server import Settings, create_app

from .helpers import assert_healthy, wait_protocol, wait_study

NOT_A_SPEC = '{"world": 5}'
CHANGES = {  # what was changed by hand -> the SQL that changes it
    "run spec, no snapshot": f"DELETE FROM snapshots; UPDATE runs SET spec = '{NOT_A_SPEC}'",
    "run spec and snapshot": "UPDATE runs SET spec = 'x'; UPDATE snapshots SET data = X'00'",
    "protocol job spec": f"UPDATE protocol_jobs SET spec = '{NOT_A_SPEC}'",
    "protocol job result": "UPDATE protocol_jobs SET result = 'not json'",
    "world spec": "UPDATE worlds SET spec = '{\"width\": -1}'",
    "study spec": "UPDATE studies SET spec = 'not json'",
    "study task": "UPDATE study_tasks SET data = '{\"episodes\": 3}'",
}
STUDY = {
    "scenario": "experiment1",
    "runs": 1,
    "measure": {"episodes": 2, "checkpoints": 1},
    "axes": [{"path": "learning.alpha", "values": [0.1]}],
}


@pytest.fixture(scope="module")
def stored(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, str]]:
    """A data directory holding a run, a world, a finished protocol job and a finished study."""
    data = tmp_path_factory.mktemp("stored") / "data"
    settings = Settings(data=data, token=None, snapshot_every=3600.0, study_executor="local")
    with TestClient(create_app(settings)) as client:
        run = client.post("/api/runs", json={"scenario": "experiment1"}).json()["id"]
        client.post(f"/api/runs/{run}/step", json={"steps": 20})
        client.put("/api/worlds/w", json={"name": "w"}).raise_for_status()
        job = client.post("/api/protocols", json={"scenario": "experiment1", "protocol": {"episodes": 2}}).json()["id"]
        assert wait_protocol(client, job)["status"] == "finished"
        study = client.post("/api/studies", json=STUDY).json()["id"]
        wait_study(client, study, "finished")
    return data, {"run": run, "job": job, "study": study}


def paths(ids: dict[str, str]) -> list[str]:
    run, job, study = ids["run"], ids["job"], ids["study"]
    return ["/api/runs", f"/api/runs/{run}", f"/api/runs/{run}/state", "/api/worlds", "/api/worlds/w",
            "/api/protocols", f"/api/protocols/{job}", "/api/studies", f"/api/studies/{study}",
            f"/api/studies/{study}/export"]  # fmt: skip


@pytest.mark.parametrize("change", list(CHANGES))
def test_a_row_that_no_longer_reads_is_left_out_and_the_rest_served(
    stored: tuple[Path, dict[str, str]], tmp_path: Path, change: str, caplog: pytest.LogCaptureFixture
) -> None:
    data = tmp_path / "data"
    shutil.copytree(stored[0], data)
    with sqlite3.connect(data / "horde.db") as db:
        db.executescript(CHANGES[change])
    ids = stored[1]
    settings = Settings(data=data, token=None, snapshot_every=3600.0, study_executor="local")
    with TestClient(create_app(settings), raise_server_exceptions=False) as client:
        answers = {path: client.get(path) for path in paths(ids)}
        answers["a run on w"] = client.post("/api/runs", json={"world": "w"})
        assert {p: r.text for p, r in answers.items() if r.status_code >= 500} == {}
        assert_healthy(client)
        listed: dict[str, Any] = {
            "run": [r["id"] for r in answers["/api/runs"].json()],
            "world": [w["name"] for w in answers["/api/worlds"].json()],
            "job": [j["id"] for j in answers["/api/protocols"].json()],
            "study": [s["id"] for s in answers["/api/studies"].json()],
        }
    left_out = change.split(" ")[0] if change != "protocol job result" else "job"
    left_out = {"protocol": "job"}.get(left_out, left_out)
    if change == "study task":  # the study stays; the configuration whose task no longer reads is left out
        assert answers[f"/api/studies/{ids['study']}"].json()["results"] == []
        left_out = ""
    for kind, names in listed.items():
        expected = ids.get(kind, "w")
        assert (expected in names) == (kind != left_out), (change, kind, names)
    assert answers["a run on w"].status_code == (404 if left_out == "world" else 201)
    if left_out:
        assert any("left out" in r.getMessage() for r in caplog.records), "the log says what was left out"
