"""Fixtures of the server tests: an app on a temporary data directory, a client, a run factory."""

from __future__ import annotations

import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

with warnings.catch_warnings():  # starlette asks for httpx2; httpx works and is what the examples use
    warnings.filterwarnings("ignore", message=".*install `httpx2`")
    from fastapi.testclient import TestClient

from horde.runs.run_setup import new_simulation
from horde.server import Settings, create_app
from horde.spec import RunSpec

from .helpers import make_spec


@pytest.fixture(scope="session", autouse=True)
def compiled_kernels() -> None:
    """Compile (or load) the core's learning kernels once, before any test times a run."""
    new_simulation(RunSpec.model_validate(make_spec())).run(10)


@pytest.fixture
def settings(tmp_path: Path) -> Settings:
    return Settings(data=tmp_path / "data", token=None, snapshot_every=3600.0, history=2000, max_runs=8)


@pytest.fixture
def client(settings: Settings) -> Iterator[TestClient]:
    with TestClient(create_app(settings)) as test_client:
        yield test_client


@pytest.fixture
def create_run(client: TestClient) -> Callable[..., str]:
    """POST a run (make_spec's, or the body given) and return its id."""

    def create(body: dict[str, Any] | None = None, **params: Any) -> str:
        response = client.post("/api/runs", json=body or make_spec(), params=params)
        assert response.status_code == 201, response.text
        return str(response.json()["id"])

    return create
