"""GET /api/runs/{id}/snapshot and POST /api/runs/import: a run resumes exactly where it stopped."""

from __future__ import annotations

import copy
from collections.abc import Callable

from fastapi.testclient import TestClient

from horde.server import Settings, create_app
from polling import wait_until

from .helpers import BASE_DEMON, locs, make_spec


def test_import_resumes_exactly(client: TestClient, create_run: Callable[..., str]) -> None:
    """Run A for n + m steps; snapshot A at n, import it as B, step B m times: identical predictions."""
    run_a = create_run()
    client.post(f"/api/runs/{run_a}/step", json={"steps": 700})
    snapshot = client.get(f"/api/runs/{run_a}/snapshot").json()
    assert snapshot["format"] == "horde-snapshot/1" and snapshot["total_steps"] == 700
    state_a = client.post(f"/api/runs/{run_a}/step", json={"steps": 900}).json()

    imported = client.post("/api/runs/import", json=snapshot)
    assert imported.status_code == 201
    run_b = imported.json()["id"]
    assert run_b != run_a and imported.json()["status"] == "paused" and imported.json()["step"] == 700
    state_b = client.post(f"/api/runs/{run_b}/step", json={"steps": 900}).json()

    assert state_b["predictions"] == state_a["predictions"]
    assert state_b["agent"] == state_a["agent"] and state_b["episode"] == state_a["episode"]
    assert state_b["metrics"] == state_a["metrics"]


def test_import_after_a_demon_joined_resumes_exactly(client: TestClient, create_run: Callable[..., str]) -> None:
    run_a = create_run()
    client.post(f"/api/runs/{run_a}/step", json={"steps": 300})
    client.post(f"/api/runs/{run_a}/demons", json={"name": "odd", "policy": "uniform", "cumulant": {"sensor": "x"}})
    client.post(f"/api/runs/{run_a}/step", json={"steps": 100})
    snapshot = client.get(f"/api/runs/{run_a}/snapshot").json()
    state_a = client.post(f"/api/runs/{run_a}/step", json={"steps": 300}).json()
    run_b = client.post("/api/runs/import", json=snapshot).json()["id"]
    assert client.post(f"/api/runs/{run_b}/step", json={"steps": 300}).json()["predictions"] == state_a["predictions"]


def test_a_finished_run_imports_as_finished(client: TestClient, create_run: Callable[..., str]) -> None:
    run_a = create_run(make_spec(episodes=1))
    # Each step request returns once its steps are taken; an episode is 100 steps at most (max_steps).
    wait_until(
        lambda: client.post(f"/api/runs/{run_a}/step", json={"steps": 50}).json()["status"] == "finished",
        "the one-episode run to finish as it is stepped",
    )
    snapshot = client.get(f"/api/runs/{run_a}/snapshot").json()
    imported = client.post("/api/runs/import", json=snapshot).json()
    assert imported["status"] == "finished"
    assert imported["summary"]["predictions"] == client.get(f"/api/runs/{run_a}").json()["summary"]["predictions"]


def test_bad_snapshots_are_422_naming_the_field(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run()
    client.post(f"/api/runs/{run_id}/step", json={"steps": 10})
    snapshot = client.get(f"/api/runs/{run_id}/snapshot").json()

    def spoiled(change: Callable[[dict], None]) -> dict:
        copied = copy.deepcopy(snapshot)
        change(copied)
        return copied

    bad_base64 = spoiled(lambda s: s["horde"]["pi"].update(data="***"))
    assert ["body", "horde", "pi"] in locs(client.post("/api/runs/import", json=bad_base64))
    wrong_shape = spoiled(lambda s: s["horde"]["pi"].update(shape=[4, 2]))
    assert ["body", "horde", "pi"] in locs(client.post("/api/runs/import", json=wrong_shape))
    missing = spoiled(lambda s: s["horde"].pop("prediction"))
    assert ["body", "horde", "prediction"] in locs(client.post("/api/runs/import", json=missing))
    other_spec = spoiled(lambda s: s["spec"].update(demons=[BASE_DEMON]))
    assert locs(client.post("/api/runs/import", json=other_spec))[0][:2] == ["body", "horde"]
    wrong_format = spoiled(lambda s: s.update(format="v0"))
    assert ["body", "format"] in locs(client.post("/api/runs/import", json=wrong_format))
    outside = spoiled(lambda s: s["world"].update(x=snapshot_array([1e6])))
    assert ["body", "world", "x"] in locs(client.post("/api/runs/import", json=outside))
    assert len(client.get("/api/runs").json()) == 1  # nothing half-imported


def snapshot_array(values: list[float]) -> dict:
    import base64

    import numpy as np

    data = base64.b64encode(np.array(values, dtype="<f8").tobytes()).decode()
    return {"dtype": "float64", "shape": [len(values)], "data": data}


def test_export_of_an_unknown_run_is_404(client: TestClient) -> None:
    assert client.get("/api/runs/nope/snapshot").status_code == 404


def test_import_is_bounded_by_the_number_of_runs(settings: Settings) -> None:
    settings = settings.model_copy(update={"max_runs": 1})
    with TestClient(create_app(settings)) as client:
        run_id = client.post("/api/runs", json=make_spec()).json()["id"]
        snapshot = client.get(f"/api/runs/{run_id}/snapshot").json()
        assert client.post("/api/runs/import", json=snapshot).status_code == 409


def test_a_float32_run_keeps_its_dtype_and_a_snapshot_that_does_not_is_422(
    client: TestClient, create_run: Callable[..., str]
) -> None:
    """`learning.dtype = "float32"` over REST: its snapshot's weights and traces are float32 and resume; a
    snapshot whose weights are not of its spec's dtype, or a dtype other than float32 / float64, is a 422 naming
    the field."""
    import base64

    import numpy as np

    run_id = create_run(make_spec(learning={"dtype": "float32"}))
    client.post(f"/api/runs/{run_id}/step", json={"steps": 300})
    snapshot = client.get(f"/api/runs/{run_id}/snapshot").json()
    assert snapshot["spec"]["learning"]["dtype"] == "float32"
    assert {snapshot["horde"][name]["dtype"] for name in ("theta.0", "w.0", "e.0", "h.0")} == {"float32"}
    assert snapshot["horde"]["prediction"]["dtype"] == "float64"  # per-demon numbers stay float64
    state_a = client.post(f"/api/runs/{run_id}/step", json={"steps": 200}).json()
    run_b = client.post("/api/runs/import", json=snapshot).json()["id"]
    state_b = client.post(f"/api/runs/{run_b}/step", json={"steps": 200}).json()
    # to float32's rounding: where the server cuts its calls decides where an owed update is rounded in
    for name, value in state_a["predictions"].items():
        assert abs(state_b["predictions"][name] - value) <= 1e-5 * max(1.0, abs(value)), name

    widened = copy.deepcopy(snapshot)
    theta = np.frombuffer(base64.b64decode(widened["horde"]["theta.0"]["data"]), "<f4").astype("<f8")
    widened["horde"]["theta.0"].update(dtype="float64", data=base64.b64encode(theta.tobytes()).decode())
    assert locs(client.post("/api/runs/import", json=widened)) == [["body", "horde", "theta.0"]]
    assert locs(client.post("/api/runs", json=make_spec(learning={"dtype": "float16"}))) == [
        ["body", "RunSpec", "learning", "dtype"]
    ]
    assert len(client.get("/api/runs").json()) == 2  # nothing half-imported or created
