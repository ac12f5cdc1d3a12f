"""Roles on the API (runs/access.py): the teacher's HORDE_TOKEN issues student and viewer tokens; a student
changes only what they created (403 naming the owner), a viewer nothing (403), a revoked token is refused
(401); the same on the WebSocket routes. Tokens are stored hashed, and they and the owners outlive a restart."""

from __future__ import annotations

import re
import sqlite3
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient
from starlette.websockets import WebSocketDisconnect

from horde.server import Settings, create_app
from horde.server.stream_protocol import StreamClose
from sockets import receive_json

from .helpers import make_spec, wait_study
from .test_stream_history import records as stream_records
from .test_stream_history import spec as stream_spec

TEACHER = {"Authorization": "Bearer s3cret"}
STUDY = {
    "scenario": "classroom-offpolicy",
    "runs": 1,
    "measure": {"episodes": 2, "checkpoints": 1},
    "axes": [{"path": "learning.alpha", "values": [0.03]}],
}
NOT_A_CHANGE = {("post", "/api/view")}  # a tab's own choice of what it watches: changes nothing anyone else sees


def bearer(token: str) -> dict[str, str]:
    return {"Authorization": f"Bearer {token}"}


@pytest.fixture
def settings(tmp_path: Path) -> Settings:
    return Settings(data=tmp_path / "data", token="s3cret", snapshot_every=3600.0, study_executor="local")


@pytest.fixture
def client(settings: Settings) -> Iterator[TestClient]:
    with TestClient(create_app(settings)) as test_client:
        yield test_client


def issue(client: TestClient, role: str, name: str) -> dict[str, Any]:
    response = client.post("/api/tokens", json={"role": role, "name": name}, headers=TEACHER)
    assert response.status_code == 201, response.text
    return dict(response.json())


def new_run(client: TestClient, headers: dict[str, str]) -> str:
    response = client.post("/api/runs", json=make_spec(), headers=headers)
    assert response.status_code == 201, response.text
    return str(response.json()["id"])


def write_routes(client: TestClient) -> list[tuple[str, str]]:
    """Every POST, PUT, PATCH and DELETE of the OpenAPI schema that changes something."""
    paths = client.get("/openapi.json").json()["paths"]
    routes = [(method, path) for path, item in paths.items() for method in item if method != "get"]
    return [route for route in routes if route not in NOT_A_CHANGE]


def test_the_teacher_issues_lists_and_revokes_tokens(client: TestClient, settings: Settings) -> None:
    alice = issue(client, "student", "alice")
    assert alice["role"] == "student" and alice["name"] == "alice"
    assert alice["token"].startswith("hl_") and alice["link"] == f"http://testserver/?token={alice['token']}"
    listed = client.get("/api/tokens", headers=TEACHER).json()
    assert [(t["id"], t["name"], t["role"]) for t in listed] == [(alice["id"], "alice", "student")]
    assert "token" not in listed[0], "a secret is shown once, when issued"
    assert client.get("/api/me", headers=bearer(alice["token"])).json() == {
        "role": "student", "id": alice["id"], "name": "alice", "tokens": True,
    }  # fmt: skip
    assert client.get("/api/me").json()["role"] == "anonymous"
    assert client.get("/api/me", headers=TEACHER).json()["role"] == "teacher"

    # Stored hashed: the secret is nowhere in the database, its SHA-256 is.
    db = sqlite3.connect(settings.data / "horde.db")
    try:
        digests = [row[0] for row in db.execute("SELECT digest FROM tokens")]
        dumped = "\n".join(db.iterdump())
    finally:
        db.close()
    assert alice["token"] not in dumped and len(digests) == 1 and len(digests[0]) == 64

    assert client.delete(f"/api/tokens/{alice['id']}", headers=TEACHER).status_code == 200
    assert client.get("/api/tokens", headers=TEACHER).json() == []
    revoked = client.get("/api/me", headers=bearer(alice["token"]))
    assert revoked.status_code == 401 and "'alice' was revoked" in revoked.json()["detail"]
    assert client.delete(f"/api/tokens/{alice['id']}", headers=TEACHER).status_code == 404


def test_bad_token_requests_name_the_field_or_the_rule(client: TestClient) -> None:
    def refused(body: dict[str, Any], headers: dict[str, str] = TEACHER) -> Any:
        return client.post("/api/tokens", json=body, headers=headers)

    unknown_role = refused({"role": "admin", "name": "eve"})
    assert unknown_role.status_code == 422 and unknown_role.json()["detail"][0]["loc"] == ["body", "role"]
    too_long = refused({"role": "student", "name": "x" * 41})
    assert too_long.status_code == 422 and too_long.json()["detail"][0]["loc"] == ["body", "name"]
    teacher_name = refused({"role": "viewer", "name": "Teacher"})
    assert teacher_name.status_code == 422 and "'teacher' names the holder" in teacher_name.text
    assert refused({"role": "student", "name": "bob"}, headers={}).status_code == 401
    bob = issue(client, "student", "bob")
    by_student = refused({"role": "student", "name": "carol"}, headers=bearer(bob["token"]))
    assert by_student.status_code == 403 and "only the teacher issues tokens" in by_student.json()["detail"]
    viewer = issue(client, "viewer", "vic")
    by_viewer = refused({"role": "student", "name": "carol"}, headers=bearer(viewer["token"]))
    assert by_viewer.status_code == 403 and "viewer changes nothing" in by_viewer.json()["detail"]
    listed_by_student = client.get("/api/tokens", headers=bearer(bob["token"]))
    assert listed_by_student.status_code == 403 and "only the teacher lists tokens" in listed_by_student.text
    assert refused({"role": "viewer", "name": "bob"}).status_code == 409, "a name in use"
    client.delete(f"/api/tokens/{bob['id']}", headers=TEACHER)
    again = refused({"role": "student", "name": "bob"})
    assert again.status_code == 409 and "issued already" in again.json()["detail"], "bob's runs name bob alone"


def test_a_student_controls_only_what_they_created(client: TestClient) -> None:
    alice = bearer(issue(client, "student", "alice")["token"])
    teachers = new_run(client, TEACHER)
    own = client.post("/api/runs", json=make_spec(), headers=alice, params={"start": True})
    assert own.status_code == 201 and own.json()["owner"] == "alice"
    own_id = own.json()["id"]
    assert client.post(f"/api/runs/{own_id}/pause", headers=alice).status_code == 200
    assert client.post(f"/api/runs/{own_id}/step", json={"steps": 3}, headers=alice).status_code == 200

    for method, path, body in [
        ("post", f"/api/runs/{teachers}/start", None),
        ("post", f"/api/runs/{teachers}/step", {"steps": 1}),
        ("patch", f"/api/runs/{teachers}", {"hz": 5}),
        ("post", f"/api/runs/{teachers}/reset", None),
        ("delete", f"/api/runs/{teachers}/demons/steps", None),
        ("post", f"/api/runs/{teachers}/evaluate", {"demon": "steps", "episodes": 2}),
        ("delete", f"/api/runs/{teachers}", None),
    ]:
        response = client.request(method, path, json=body, headers=alice)
        assert response.status_code == 403, (method, path, response.text)
        assert (
            response.json()["detail"]
            == f"run '{teachers}' belongs to 'teacher': a student changes only what they created"
        )
    owners = {r["id"]: r["owner"] for r in client.get("/api/runs").json()}
    assert owners == {teachers: "teacher", own_id: "alice"}
    assert client.get(f"/api/runs/{teachers}").json()["status"] == "created", "nothing of the refused was done"

    # Worlds: a student stores their own, and may not replace or delete the teacher's.
    world = make_spec()["world"]
    assert client.put("/api/worlds/shared", json=world, headers=TEACHER).status_code == 201
    assert client.put("/api/worlds/shared", json=world, headers=alice).status_code == 403
    assert client.delete("/api/worlds/shared", headers=alice).status_code == 403
    assert client.post("/api/worlds", json={**world, "name": "mine"}, headers=alice).status_code == 201
    assert client.put("/api/worlds/mine", json=world, headers=alice).status_code == 200
    assert {w["name"]: w["owner"] for w in client.get("/api/worlds").json()} == {"mine": "alice", "shared": "teacher"}
    assert client.delete("/api/worlds/mine", headers=alice).status_code == 204
    # The teacher controls everything, a student's too.
    assert client.delete(f"/api/runs/{own_id}", headers=TEACHER).status_code == 204


def test_a_students_study_and_stream_run_are_theirs(client: TestClient) -> None:
    alice = bearer(issue(client, "student", "alice")["token"])
    bob = bearer(issue(client, "student", "bob")["token"])
    started = client.post("/api/studies", json=STUDY, headers=alice)
    assert started.status_code == 202 and started.json()["owner"] == "alice"
    study = started.json()["id"]
    wait_study(client, study, "finished")
    refused = client.delete(f"/api/studies/{study}", headers=bob)
    assert refused.status_code == 403 and "belongs to 'alice'" in refused.json()["detail"]
    assert client.delete(f"/api/studies/{study}", headers=alice).status_code == 200

    stream = client.post("/api/streams", json=stream_spec(), headers=alice).json()
    assert stream["owner"] == "alice"
    records = {"records": stream_records(2)}
    pushed = client.post(f"/api/streams/{stream['id']}/records", json=records, headers=bob)
    assert pushed.status_code == 403 and "belongs to 'alice'" in pushed.json()["detail"]
    assert client.post(f"/api/streams/{stream['id']}/records", json=records, headers=alice).status_code == 200


def test_a_viewer_changes_nothing_and_a_revoked_token_nothing_either(client: TestClient) -> None:
    """Every route that changes something, read from the OpenAPI schema: 403 for a viewer's token, 401 for a
    revoked one, before the route looks at its path or body."""
    viewer = issue(client, "viewer", "vic")
    student = issue(client, "student", "sam")
    assert client.delete(f"/api/tokens/{student['id']}", headers=TEACHER).status_code == 200
    routes = write_routes(client)
    assert len(routes) >= 25, routes
    for method, path in routes:
        concrete = re.sub(r"\{\w+\}", "x", path)
        as_viewer = client.request(method, concrete, json={}, headers=bearer(viewer["token"]))
        assert as_viewer.status_code == 403, (method, path, as_viewer.text)
        assert "a viewer changes nothing" in as_viewer.json()["detail"]
        as_revoked = client.request(method, concrete, json={}, headers=bearer(student["token"]))
        assert as_revoked.status_code == 401, (method, path, as_revoked.text)


def test_the_websockets_refuse_a_revoked_token_and_records_check_the_owner(client: TestClient) -> None:
    alice = issue(client, "student", "alice")
    viewer = issue(client, "viewer", "vic")
    gone = issue(client, "student", "gone")
    client.delete(f"/api/tokens/{gone['id']}", headers=TEACHER)
    teachers = client.post("/api/streams", json=stream_spec(), headers=TEACHER).json()["id"]
    own = client.post("/api/streams", json=stream_spec(), headers=bearer(alice["token"])).json()["id"]
    run = new_run(client, TEACHER)

    def close_code(path: str) -> tuple[int, str]:
        with pytest.raises(WebSocketDisconnect) as closed, client.websocket_connect(path) as ws:
            receive_json(ws, f"a close of {path}")
        return closed.value.code, closed.value.reason

    for path in (f"/api/runs/{run}/stream", f"/api/streams/{own}/records", "/api/studies/x/stream"):
        code, reason = close_code(f"{path}?token={gone['token']}")
        assert code == StreamClose.UNAUTHORIZED and "revoked" in reason, path
    code, reason = close_code(f"/api/streams/{teachers}/records?token={alice['token']}")
    assert code == StreamClose.FORBIDDEN and "belongs to 'teacher'" in reason
    code, reason = close_code(f"/api/streams/{own}/records?token={viewer['token']}")
    assert code == StreamClose.FORBIDDEN and "viewer changes nothing" in reason
    with client.websocket_connect(f"/api/streams/{own}/records?token={alice['token']}") as ws:
        assert receive_json(ws, "the hello")["type"] == "hello"
        ws.send_json({"records": stream_records(2)})
        assert receive_json(ws, "the learned message")["type"] == "learned"
    with client.websocket_connect(f"/api/runs/{run}/stream?token={viewer['token']}") as ws:  # reading is a viewer's
        assert receive_json(ws, "the run's state")["type"] == "state"


def test_tokens_and_owners_outlive_a_restart(settings: Settings) -> None:
    with TestClient(create_app(settings)) as client:
        alice = issue(client, "student", "alice")
        run = new_run(client, bearer(alice["token"]))
    with TestClient(create_app(settings)) as client:
        assert client.get(f"/api/runs/{run}").json()["owner"] == "alice"
        assert client.post(f"/api/runs/{run}/step", headers=bearer(alice["token"])).status_code == 200
        assert client.get("/api/me", headers=bearer(alice["token"])).json()["name"] == "alice"


def test_without_horde_token_everyone_is_the_teacher(tmp_path: Path) -> None:
    with TestClient(create_app(Settings(data=tmp_path / "data", token=None))) as client:
        assert client.get("/api/me").json() == {"role": "teacher", "id": "teacher", "name": "teacher", "tokens": False}
        run = new_run(client, {})
        assert client.get(f"/api/runs/{run}").json()["owner"] == "teacher"
        refused = client.post("/api/tokens", json={"role": "student", "name": "alice"})
        assert refused.status_code == 409 and "HORDE_TOKEN" in refused.json()["detail"]
