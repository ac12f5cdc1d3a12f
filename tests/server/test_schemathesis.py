"""Schemathesis over every route, in process against the ASGI app: no 5xx, no response off the schema.

Two phases: the coverage phase (every boundary and every kind of wrong value the schema defines, for
every operation) and the fuzzing phase (at most MAX_EXAMPLES generated cases per operation); no stateful
phase. Hooks put the id of a real run (and real demon and world names) into most generated paths, so
the operations are exercised on live resources as well as on unknown ones (404), and turn some
generated bodies into what no schema describes: a number replaced by NaN, Infinity or -Infinity (JSON
as Python and JavaScript write it), or an object nested hundreds of levels deep.
"""

from __future__ import annotations

import atexit
import json
import math
import random
import shutil
import tempfile
import tomllib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import schemathesis
from hypothesis import HealthCheck, settings
from schemathesis.checks import not_a_server_error
from schemathesis.config import SchemathesisConfig
from schemathesis.python import asgi
from schemathesis.specs.openapi.checks import (
    content_type_conformance,
    response_headers_conformance,
    response_schema_conformance,
    status_code_conformance,
)

from horde.server import Settings, create_app

# One process: schemathesis gives every operation's item the same test id, and pytest-xdist runs items by id, so
# in two processes it ran one operation instead of all sixty (make test runs this file whole, in a process of its own).
pytestmark = pytest.mark.serial

MAX_EXAMPLES = 20
# Made when the module is imported: every test process that collects it (also those that deselect its tests)
# removes it as it exits.
DATA = Path(tempfile.mkdtemp(prefix="horde-schemathesis-"))
atexit.register(shutil.rmtree, DATA, ignore_errors=True)
APP = create_app(Settings(data=DATA, token=None, max_runs=16, snapshot_every=3600.0, study_executor="local"))
# The settings the long run of docs/hardening.md shares (which operations skip the coverage phase, and why),
# with this run's number of examples and its coverage phase on.
CONFIG = SchemathesisConfig.from_dict(
    tomllib.loads((Path(__file__).parent / "schemathesis.toml").read_text())
    | {
        "generation": {"max-examples": MAX_EXAMPLES},
        "phases": {"coverage": {"enabled": True}, "stateful": {"enabled": False}},
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


def _live_run(client: asgi.ASGIClient) -> None:
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


NON_FINITE = (math.nan, math.inf, -math.inf)
DEEP = 300  # levels of the nested object put into some bodies


def _numbers(value: Any, path: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Paths of the numbers (not booleans) in a JSON value."""
    if isinstance(value, dict):
        return [p for key, item in value.items() for p in _numbers(item, (*path, key))]
    if isinstance(value, list):
        return [p for i, item in enumerate(value) for p in _numbers(item, (*path, i))]
    return [path] if isinstance(value, int | float) and not isinstance(value, bool) else []


def _replace(value: Any, path: tuple[Any, ...], new: Any) -> Any:
    if not path:
        return new
    copy = dict(value) if isinstance(value, dict) else list(value)
    copy[path[0]] = _replace(copy[path[0]], path[1:], new)
    return copy


@schema.hook
def map_body(context: schemathesis.HookContext, body: Any) -> Any:
    """One generated body in three gets a non-finite number, one in six a deeply nested object."""
    rng = random.Random(json.dumps(body, sort_keys=True, default=str))
    roll = rng.random()
    if roll < 1 / 3:
        numbers = _numbers(body)
        if numbers:  # as bytes: JSON encoders refuse NaN, Python's json writes it as browsers' JSON.parse would not
            return json.dumps(_replace(body, rng.choice(numbers), rng.choice(NON_FINITE))).encode()
    elif roll < 1 / 2 and isinstance(body, dict) and body:
        deep: Any = 1
        for _ in range(DEEP):
            deep = {"add": [deep, 1]}
        return {**body, rng.choice(sorted(body)): deep}
    return body


@pytest.fixture(scope="module")
def client() -> Iterator[asgi.ASGIClient]:
    """The app's one lifespan (store, run manager) around the generated calls: schemathesis's own client,
    which every case is sent through, so that the app never runs two lifespans at once."""
    with asgi.get_client(APP) as client:
        _live_run(client)
        yield client
    asgi.shutdown_lifespans()


@schema.parametrize()
@settings(
    max_examples=MAX_EXAMPLES,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much, HealthCheck.data_too_large],
)
def test_api(case: schemathesis.Case, client: asgi.ASGIClient) -> None:
    _live_run(client)
    case.call_and_validate(session=client, checks=CHECKS)
