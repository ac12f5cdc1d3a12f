"""Imports are untrusted input (issue 24, item 1): every array of a snapshot is checked against its spec
before it reaches the compiled engine, and refused with a 422 naming the entry.

Before, an active-feature index of 10**12 was a 201 and starting the run segfaulted the server; an index
200 past its table read and wrote memory out of range silently; NaN and infinite weights were 201s; and a
`total_steps` of 10**30 was a 503 that left the run in memory unsaved. After each refusal the server holds
no new run and /api/health answers promptly.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from pathlib import Path
from typing import Any
from unittest import mock

import numpy as np
import pytest
from fastapi.testclient import TestClient

from horde.runs.snapshot import EncodedArray, Snapshot, decode, encode, to_bytes
from horde.runs.store import Store
from horde.server import Settings, create_app
from stream_specs import LIGHT_WHEEL, nexting, robot, tiled

from .helpers import assert_healthy, locs, make_spec
from .test_divergence import WILD

STRIPES_FEATURES = 29  # the stripes of make_spec's world (parts = 5): the table the active indices point into


def array(values: Any, dtype: str) -> dict[str, Any]:
    return encode(np.array(values, dtype=dtype)).model_dump()


def decoded(entry: dict[str, Any]) -> np.ndarray:
    return decode(EncodedArray.model_validate(entry), ())


@pytest.fixture
def snapshot(client: TestClient, create_run: Callable[..., str]) -> dict[str, Any]:
    run_id = create_run()
    client.post(f"/api/runs/{run_id}/step", json={"steps": 30})
    exported: dict[str, Any] = client.get(f"/api/runs/{run_id}/snapshot").json()
    return exported


def spoiled(snapshot: dict[str, Any], part: str, path: str, change: Callable[[np.ndarray], None]) -> dict[str, Any]:
    """A copy of the snapshot with one array changed in place by `change`."""
    copied = copy.deepcopy(snapshot)
    values = decoded(copied[part][path])
    change(values)
    copied[part][path] = array(values, values.dtype.name)
    return copied


def refused_at(client: TestClient, body: dict[str, Any], loc: list[Any], path: str = "/api/runs/import") -> str:
    """Post the body; assert a 422 at `loc`, that no run was made and that the server answers; return the message."""
    before = len(client.get("/api/runs").json())
    response = client.post(path, json=body)
    assert loc in locs(response), response.text
    assert len(client.get("/api/runs").json()) == before
    assert_healthy(client)
    return str(response.json()["detail"][0]["msg"])


def set_at(index: int, value: float) -> Callable[[np.ndarray], None]:
    def change(values: np.ndarray) -> None:
        values.reshape(-1)[index] = value

    return change


def test_an_active_feature_index_of_10_to_the_12_is_refused(client: TestClient, snapshot: dict[str, Any]) -> None:
    message = refused_at(client, spoiled(snapshot, "horde", "features.0", set_at(0, 10**12)),
                         ["body", "horde", "features.0"])  # fmt: skip
    assert f"[0, {STRIPES_FEATURES})" in message


def test_an_index_200_past_its_table_is_refused(client: TestClient, snapshot: dict[str, Any]) -> None:
    refused_at(client, spoiled(snapshot, "horde", "features.1", set_at(2, STRIPES_FEATURES + 200)),
               ["body", "horde", "features.1"])  # fmt: skip
    refused_at(client, spoiled(snapshot, "horde", "features.0", set_at(0, -1)), ["body", "horde", "features.0"])


@pytest.mark.parametrize("value", [float("nan"), float("inf"), float("-inf")])
def test_non_finite_weights_and_traces_are_refused(client: TestClient, snapshot: dict[str, Any], value: float) -> None:
    for path in ("theta.0", "w.1", "e.0", "h.0", "delta_e.1"):
        message = refused_at(client, spoiled(snapshot, "horde", path, set_at(3, value)), ["body", "horde", path])
        assert "finite" in message
    refused_at(client, spoiled(snapshot, "horde", "prediction", set_at(0, value)), ["body", "horde", "prediction"])


def test_arrays_their_data_cannot_fill_are_refused_before_a_worker_is_started(
    client: TestClient, snapshot: dict[str, Any]
) -> None:
    """Schemathesis's slowest answer (12 s under its load): shapes of 10**8 x 10**4 over a few bytes, refused
    only once a worker had been forked to build the run. Now refused on arrival, as the document is read."""
    executor = client.app.state.manager.executor  # type: ignore[attr-defined]
    never = mock.patch.object(executor, "spawn", side_effect=AssertionError("a worker was started"))
    never.start()
    huge = copy.deepcopy(snapshot)
    huge["horde"]["theta.0"] = {"dtype": "int64", "shape": [231031272, 33876], "data": ""}
    message = refused_at(client, huge, ["body", "horde", "theta.0"])
    assert message == "0 bytes do not fill shape [231031272, 33876] of int64"
    short = copy.deepcopy(snapshot)
    short["stop_reference"] = [{"dtype": "float32", "shape": [], "data": "AAA="}]  # 2 bytes where 4 are needed
    assert refused_at(client, short, ["body", "stop_reference", 0]) == "2 bytes do not fill shape [] of float32"
    not_base64 = copy.deepcopy(snapshot)
    not_base64["world"]["x"]["data"] = "AAAAA"
    assert "not valid base64" in refused_at(client, not_base64, ["body", "world", "x"])
    never.stop()


def test_counts_beyond_sqlite_integers_are_refused(client: TestClient, snapshot: dict[str, Any]) -> None:
    for field in ("total_steps", "episode"):
        refused_at(client, {**snapshot, field: 10**30}, ["body", field])
    refused_at(client, spoiled(snapshot, "world", "steps", set_at(0, -5)), ["body", "world", "steps"])


def test_a_generator_state_beyond_128_bits_is_refused(client: TestClient, snapshot: dict[str, Any]) -> None:
    refused_at(client, {**snapshot, "rng": {**snapshot["rng"], "state": str(2**128)}}, ["body", "rng", "state"])


def test_an_indicator_colour_outside_its_indicator_is_refused(client: TestClient) -> None:
    run_id = client.post("/api/runs", json={"scenario": "experiment3"}).json()["id"]
    snapshot = client.get(f"/api/runs/{run_id}/snapshot").json()
    refused_at(client, spoiled(snapshot, "world", "colors", set_at(0, 2)), ["body", "world", "colors"])


def test_an_export_with_diverged_demons_imports_again(client: TestClient, create_run: Callable[..., str]) -> None:
    """The engine leaves NaN in a state-value demon's action values and in what a diverged demon holds: a real
    export carrying them is taken back (the checks refuse only what no run produces)."""
    run_id = create_run(make_spec(demons=make_spec()["demons"] + WILD))
    client.post(f"/api/runs/{run_id}/step", json={"steps": 500})
    snapshot = client.get(f"/api/runs/{run_id}/snapshot").json()
    diverged = decoded(snapshot["horde"]["diverged"])
    assert diverged.tolist() == [False, False, True, True]
    assert np.isnan(decoded(snapshot["horde"]["q"])).any()
    imported = client.post("/api/runs/import", json=snapshot)
    assert imported.status_code == 201, imported.text
    # The same NaN in a demon that did not diverge is refused.
    healthy_slot = 0  # "base", the first demon
    refused_at(client, spoiled(snapshot, "horde", "prediction", set_at(healthy_slot, float("nan"))),
               ["body", "horde", "prediction"])  # fmt: skip


def test_a_stream_import_is_checked_alike(client: TestClient) -> None:
    spec = robot(tiled(LIGHT_WHEEL, tilings=2, tiles=4, size=64), nexting("light", 0.5))
    run = client.post("/api/streams", json=spec).json()["id"]
    records = [{"observation": [0.5, 0.1], "action": 0, "behaviour_probabilities": [0.5, 0.5]}] * 5
    client.post(f"/api/streams/{run}/records", json={"records": records})
    snapshot = client.get(f"/api/streams/{run}/snapshot").json()
    assert client.post("/api/streams/import", json=snapshot).status_code == 201
    streams = len(client.get("/api/streams").json())

    def refused(body: dict[str, Any], loc: list[Any]) -> None:
        assert loc in locs(client.post("/api/streams/import", json=body))
        assert len(client.get("/api/streams").json()) == streams
        assert_healthy(client)

    refused(spoiled(snapshot, "horde", "features.0", set_at(0, 10**12)), ["body", "horde", "features.0"])
    refused(spoiled(snapshot, "horde", "theta.0", set_at(0, float("inf"))), ["body", "horde", "theta.0"])
    sensors = decoded(snapshot["sensors"])
    sensors[1] = float("nan")
    refused({**snapshot, "sensors": array(sensors, "float64")}, ["body", "sensors"])
    refused({**snapshot, "received": 10**30}, ["body", "received"])


def test_a_stored_run_whose_snapshot_is_out_of_range_comes_back_failed(settings: Settings, tmp_path: Path) -> None:
    """A snapshot tampered with in the store does not reach the engine at start-up: the run comes back failed,
    saying why, and the server serves."""
    with TestClient(create_app(settings)) as client:
        run_id = client.post("/api/runs", json=make_spec()).json()["id"]
        client.post(f"/api/runs/{run_id}/step", json={"steps": 30})
        client.post(f"/api/runs/{run_id}/pause")
        snapshot = client.get(f"/api/runs/{run_id}/snapshot").json()
    bad = Snapshot.model_validate(spoiled(snapshot, "horde", "features.0", set_at(0, 10**12)))
    store = Store(settings.data)
    record = next(r for r in store.list_runs() if r.id == run_id)
    store.save_run(record, to_bytes(bad))
    store.close()
    with TestClient(create_app(settings)) as client:
        run = client.get(f"/api/runs/{run_id}").json()
        assert run["status"] == "failed" and "features.0" in run["message"], run
        assert_healthy(client)
