"""Snapshot imports share one body limit (issue 24, item 7): a stream run takes back its own export.

The shipped `mountaincar-log` stream run exports a snapshot of about 1.2 MB, beyond the 1 MiB every other
body may have; `POST /api/streams/import` used to answer it 413. Both imports now have HORDE_MAX_IMPORT_BODY.
"""

from __future__ import annotations

from fastapi.testclient import TestClient

from horde.server import Settings, create_app

from .helpers import assert_healthy


def mountaincar_snapshot(client: TestClient) -> tuple[str, bytes]:
    spec = client.get("/api/scenarios/mountaincar-log").json()
    run = client.post("/api/streams", json=spec)
    assert run.status_code == 201, run.text
    records = [{"observation": [-0.5, 0.01 * (i % 3 - 1)], "action": i % 3, "behaviour_probabilities": [0.8, 0.1, 0.1]}
               for i in range(20)]  # fmt: skip
    client.post(f"/api/streams/{run.json()['id']}/records", json={"records": records}).raise_for_status()
    return run.json()["id"], client.get(f"/api/streams/{run.json()['id']}/snapshot").content


def test_the_mountaincar_log_stream_run_imports_its_own_export(client: TestClient, settings: Settings) -> None:
    run_id, body = mountaincar_snapshot(client)
    assert len(body) > settings.max_body  # larger than any other request may be
    imported = client.post("/api/streams/import", content=body, headers={"content-type": "application/json"})
    assert imported.status_code == 201, imported.text
    assert imported.json()["predictions"] == client.get(f"/api/streams/{run_id}").json()["predictions"]
    assert_healthy(client)


def test_both_imports_are_bounded_by_the_import_limit(settings: Settings) -> None:
    with TestClient(create_app(settings)) as client:
        _, body = mountaincar_snapshot(client)
        run_id = client.post("/api/runs", json={"scenario": "experiment1"}).json()["id"]
        run_body = client.get(f"/api/runs/{run_id}/snapshot").content
    small = settings.model_copy(update={"max_import_body": min(len(body), len(run_body)) - 1})
    with TestClient(create_app(small)) as client:
        for path, content in (("/api/streams/import", body), ("/api/runs/import", run_body)):
            response = client.post(path, content=content, headers={"content-type": "application/json"})
            assert response.status_code == 413, (path, response.text)
            assert str(small.max_import_body) in response.json()["detail"]
        assert_healthy(client)
