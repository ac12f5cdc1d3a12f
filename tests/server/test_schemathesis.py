"""Schemathesis over every route, in process against the ASGI app: no 5xx, no response off the schema.

Bounded in time: at most MAX_EXAMPLES generated cases per operation, no coverage or stateful phase.
A hook puts the id of a real run (and real demon and world names) into most generated paths, so the
operations are exercised on live resources as well as on unknown ones (404).
"""

from __future__ import annotations

import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import schemathesis
from fastapi.testclient import TestClient
from hypothesis import HealthCheck, settings
from schemathesis.checks import not_a_server_error
from schemathesis.config import SchemathesisConfig
from schemathesis.specs.openapi.checks import (
    content_type_conformance,
    response_headers_conformance,
    response_schema_conformance,
    status_code_conformance,
)

from horde.server import Settings, create_app

MAX_EXAMPLES = 20
DATA = Path(tempfile.mkdtemp(prefix="horde-schemathesis-"))
APP = create_app(Settings(data=DATA, token=None, max_runs=16, snapshot_every=3600.0, study_executor="local"))
CONFIG = SchemathesisConfig.from_dict(
    {
        "generation": {"max-examples": MAX_EXAMPLES},
        "phases": {"coverage": {"enabled": False}, "stateful": {"enabled": False}},
    }
)
schema = schemathesis.openapi.from_asgi("/openapi.json", APP, config=CONFIG)
CHECKS = [
    not_a_server_error,
    status_code_conformance,
    content_type_conformance,
    response_headers_conformance,
    response_schema_conformance,
]


LIVE: dict[str, str] = {"run_id": "", "name": "steps_to_end"}


def _live_run(client: TestClient) -> None:
    """Make sure the live run, its demon and the world exist (generated DELETEs remove them)."""
    if not LIVE["run_id"] or client.get(f"/api/runs/{LIVE['run_id']}").status_code == 404:
        created = client.post("/api/runs", json={"scenario": "experiment1", "protocol": {"episodes": 0}})
        LIVE["run_id"] = created.json()["id"]
    demons = f"/api/runs/{LIVE['run_id']}/demons"
    if client.get(f"{demons}/{LIVE['name']}").status_code == 404:
        client.post(demons, json={"name": LIVE["name"], "policy": {"of": "base"}, "cumulant": 1})
    client.post("/api/worlds", json={"name": "room"})


@schema.hook
def map_path_parameters(context: schemathesis.HookContext, path_parameters: dict[str, Any]) -> dict[str, Any]:
    """Three generated paths in four name the live run, demon and world."""
    if not path_parameters or not LIVE["run_id"]:
        return path_parameters
    mapped = dict(path_parameters)
    for key, value in path_parameters.items():
        if len(str(value)) % 4 != 0:
            mapped[key] = {"run_id": LIVE["run_id"], "name": LIVE["name"]}.get(key, value)
            if key == "name" and "/worlds/" in context.operation.path:
                mapped[key] = "room"
    return mapped


@pytest.fixture(scope="module")
def client() -> Iterator[TestClient]:
    """The app's lifespan (store, run manager) around the generated calls."""
    with TestClient(APP) as client:
        _live_run(client)
        yield client
    shutil.rmtree(DATA, ignore_errors=True)


@schema.parametrize()
@settings(
    max_examples=MAX_EXAMPLES,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much, HealthCheck.data_too_large],
)
def test_api(case: schemathesis.Case, client: TestClient) -> None:
    _live_run(client)
    case.call_and_validate(checks=CHECKS)
