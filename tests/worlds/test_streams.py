"""Stream runs: records over REST and the WebSocket, bad records named and skipped, a log learned at full speed.

The central test pushes 100,000 records over the WebSocket from another process (examples/07_stream_replay.py
against the real server in a thread) and checks that every record was learned, in order: the final
predictions equal those of `horde run --log` over the same records as a CSV log, exactly.
"""

from __future__ import annotations

import csv
import json
import subprocess
import sys
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

with warnings.catch_warnings():
    warnings.filterwarnings("ignore", message=".*install `httpx2`")
    from fastapi.testclient import TestClient

from horde.cli import main as horde_main
from horde.server import Settings, create_app
from horde.spec import RunSpec
from horde.worlds.log_run import learn_log
from serving import serve_in_thread
from sockets import receive_json
from stream_specs import tiled

ROOT = Path(__file__).resolve().parents[2]
SENSORS = [{"name": "light", "low": 0, "high": 1}, {"name": "wheel", "low": -1, "high": 1},
           {"name": "heat", "low": 20, "high": 40}]  # fmt: skip


def stream_spec() -> dict[str, Any]:
    return {
        "world": {"kind": "stream", "actions": 3, "sensors": SENSORS},
        "features": tiled(SENSORS, tilings=4, tiles=6, size=512),
        "families": [{"name": "{s}_g{gamma}", "over": {"s": ["light", "wheel", "heat"], "gamma": [0, 0.5, 0.9]},
                      "demon": {"learner": "td", "cumulant": {"sensor": "{s}"}, "discount": "{gamma}"}}],
        "demons": [{"name": "light_if_left", "learner": "gq", "cumulant": {"sensor": "light"}, "discount": 0.8,
                    "policy": {"kind": "fixed", "probabilities": [0.8, 0.1, 0.1]}}],
    }  # fmt: skip


def write_log(path: Path, n: int, seed: int = 0) -> None:
    """n records of a wandering robot: smooth sensors, actions drawn from logged, state-dependent probabilities."""
    rng = np.random.default_rng(seed)
    t = np.arange(n)
    light = 0.5 + 0.4 * np.sin(t / 50.0) + 0.05 * rng.standard_normal(n)
    wheel = np.clip(np.cos(t / 17.0) + 0.1 * rng.standard_normal(n), -1, 1)
    heat = 30 + 8 * np.sin(t / 300.0)
    with path.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["light", "wheel", "heat", "action", "b0", "b1", "b2"])
        for i in range(n):
            probs = [0.6, 0.2, 0.2] if wheel[i] > 0 else [0.2, 0.2, 0.6]
            writer.writerow([f"{light[i]:.6f}", f"{wheel[i]:.6f}", f"{heat[i]:.6f}", rng.choice(3, p=probs),
                             *probs])  # fmt: skip


@pytest.fixture
def client(tmp_path: Path) -> Iterator[TestClient]:
    settings = Settings(data=tmp_path / "data", token=None, snapshot_every=3600.0)
    with TestClient(create_app(settings)) as test_client:
        yield test_client


def test_rest_batches_are_all_or_nothing_and_name_the_field(client: TestClient) -> None:
    created = client.post("/api/streams", json=stream_spec())
    assert created.status_code == 201, created.text
    run = created.json()
    assert run["sensors"] == ["light", "wheel", "heat"] and run["actions"] == 3 and len(run["demons"]) == 10
    good = {"observation": [0.5, 0.1, 30.0], "action": 1}
    url = f"/api/streams/{run['id']}/records"
    cases = [
        ({"observation": [0.5, 0.1], "action": 1}, ["body", "records", 1, "observation"], "2 readings"),
        ({"observation": [0.5, "NaN", 30.0], "action": 1}, ["body", "records", 1, "observation", "wheel"], "nan"),
        ({"observation": [0.5, 0.1, 30.0], "action": 3}, ["body", "records", 1, "action"], "not one of"),
        ({"observation": [0.5, 0.1, 30.0], "action": 0, "behaviour_probabilities": [0, 0.5, 0.5]},
         ["body", "records", 1, "behaviour_probabilities"], "probability 0"),
    ]  # fmt: skip
    for bad, loc, words in cases:
        response = client.post(url, json={"records": [good, bad]})
        assert response.status_code == 422, response.text
        [problem] = response.json()["detail"]
        assert problem["loc"] == loc and words in problem["msg"], problem
    assert client.get(f"/api/streams/{run['id']}").json()["received"] == 0, "a refused batch is learned not at all"
    response = client.post(url, json={"records": [good, good]})
    assert response.status_code == 200 and response.json()["learned"] == 2
    assert client.post("/api/streams", json={"world": {"kind": "grid"}}).json()["detail"][0]["loc"] == [
        "body", "world", "kind"]  # fmt: skip
    assert client.post("/api/streams/nope/records", json={"records": [good]}).status_code == 404
    gym = {"world": {"kind": "gymnasium", "id": "NoSuchEnv-v0"}}  # no stream: refused before any environment is made
    assert client.post("/api/streams", json=gym).json()["detail"][0]["loc"] == ["body", "world", "kind"]


def test_the_websocket_reports_bad_records_and_goes_on(client: TestClient) -> None:
    run = client.post("/api/streams", json=stream_spec()).json()
    good = {"observation": [0.5, 0.1, 30.0], "action": 1}
    with client.websocket_connect(f"/api/streams/{run['id']}/records") as socket:
        assert receive_json(socket, "the hello")["type"] == "hello"
        socket.send_text(json.dumps({"records": [good, {"observation": [0.5, 0.1, float("nan")], "action": 1}, good]}))
        error = receive_json(socket, "the error for the NaN record")
        assert error == {
            "type": "error",
            "index": 1,
            "field": "observation.heat",
            "message": "nan is not a finite number",
        }
        learned = receive_json(socket, "the learned count")
        assert learned["type"] == "learned" and learned["received"] == 3 and learned["learned"] == 2
        socket.send_text("not json")
        assert receive_json(socket, "the error for a message that is not JSON")["field"] == "message"
        socket.send_text(json.dumps({"records": [good] * 10_001}))
        assert "at most 10000 records a message" in receive_json(socket, "the error for too many records")["message"]
        socket.send_text(json.dumps(good))
        assert receive_json(socket, "the learned count")["learned"] == 3
    with pytest.raises(Exception), client.websocket_connect("/api/streams/nope/records") as socket:  # noqa: B017
        receive_json(socket, "a message on an unknown stream")


def test_a_log_with_bad_lines_names_file_line_and_field(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    log = tmp_path / "log.csv"
    write_log(log, 50)
    lines = log.read_text().splitlines()
    lines[3] = lines[3].replace(lines[3].split(",")[1], "nan", 1)
    lines[7] = ",".join([*lines[7].split(",")[:3], "9", *lines[7].split(",")[4:]])
    log.write_text("\n".join(lines) + "\n")
    scenario = tmp_path / "s.toml"
    import tomli_w

    scenario.write_text(tomli_w.dumps({"description": "test", **stream_spec()}))
    assert horde_main(["run", str(scenario), "--log", str(log), "--quiet"]) == 0
    out = capsys.readouterr().out
    assert f"refused {log}:4: observation.wheel: nan is not a finite number" in out
    assert f"refused {log}:8: action: 9 is not one of the stream's 3 actions" in out
    assert "50 records, 48 learned, 2 refused" in out


def test_a_log_compares_each_prediction_with_its_realised_return(tmp_path: Path) -> None:
    """On the recorded MountainCar log, the on-policy demons' mean predictions sit near the realised returns."""
    from horde.scenarios import load_scenario

    spec = load_scenario(ROOT / "scenarios" / "mountaincar-log.toml")
    result = learn_log(spec, ROOT / "examples" / "data" / "mountaincar-pump.csv")
    assert result.learned == result.records == 10_000 and not result.refused
    for demon in result.demons:
        assert demon.mean_prediction is not None and demon.mean_return is not None
        if demon.name.startswith("position") and not demon.name.endswith("0.98"):
            assert demon.mean_prediction == pytest.approx(demon.mean_return, rel=0.05), demon


@pytest.mark.slow
def test_100k_records_over_the_websocket_from_another_process_equal_the_csv_log(tmp_path: Path) -> None:
    import httpx

    log = tmp_path / "log.csv"
    write_log(log, 100_000)
    spec = RunSpec.model_validate(stream_spec())
    expected = learn_log(spec, log)
    assert expected.learned == 100_000
    with serve_in_thread(
        Settings(data=tmp_path / "data", token=None, snapshot_every=3600.0), ws_max_size=2**24
    ) as server:
        url = server.url
        run = httpx.post(f"{url}/api/streams", json=stream_spec(), timeout=60).json()
        out = tmp_path / "out.json"
        replay = subprocess.run(
            [sys.executable, str(ROOT / "examples" / "07_stream_replay.py"), str(log), "--url", url, "--stream",
             run["id"], "--hz", "0", "--batch", "500", "--out", str(out), "--timeout", "300"],
            capture_output=True, text=True, timeout=600,
        )  # fmt: skip
        assert replay.returncode == 0, replay.stdout + replay.stderr
        result = json.loads(out.read_text())
        assert result["received"] == result["learned"] == 100_000 and not result["errors"]
        served = httpx.get(f"{url}/api/streams/{run['id']}", timeout=60).json()
        assert served["learned"] == 100_000
        names = [d.name for d in spec.demons]
        np.testing.assert_array_equal(
            [result["predictions"][n] for n in names], [d.prediction for d in expected.demons]
        )
        np.testing.assert_array_equal(
            [served["predictions"][n] for n in names], [d.prediction for d in expected.demons]
        )
        rate = 100_000 / result["seconds"]
        print(f"100,000 records over the WebSocket in {result['seconds']:.1f} s ({rate:,.0f} records/s); "
              f"the CSV log: {expected.records_per_second:,.0f} records/s")  # fmt: skip


@pytest.mark.timeout(180)
def test_the_replay_example_deletes_the_stream_run_it_started_unless_asked_to_keep_it(tmp_path: Path) -> None:
    import httpx

    log = ROOT / "examples" / "data" / "mountaincar-pump.csv"
    with serve_in_thread(Settings(data=tmp_path / "data", token=None, snapshot_every=3600.0)) as server:
        for extra, left in (([], 0), (["--keep"], 1)):
            replay = subprocess.run(
                [sys.executable, str(ROOT / "examples" / "07_stream_replay.py"), str(log), "--url", server.url,
                 "--hz", "0", "--batch", "500", "--timeout", "120", *extra],
                capture_output=True, text=True, timeout=150,
            )  # fmt: skip
            assert replay.returncode == 0, replay.stdout + replay.stderr
            assert "learned in all" in replay.stdout
            assert len(httpx.get(f"{server.url}/api/streams", timeout=60).json()) == left, extra


def test_the_recording_example_writes_a_log_the_stream_scenario_reads(tmp_path: Path) -> None:
    from horde.scenarios import load_scenario

    out = tmp_path / "log.csv"
    done = subprocess.run([sys.executable, str(ROOT / "examples" / "06_record_a_log.py"), "--records", "300",
                           "--out", str(out)], capture_output=True, text=True, timeout=120)  # fmt: skip
    assert done.returncode == 0, done.stderr
    result = learn_log(load_scenario(ROOT / "scenarios" / "mountaincar-log.toml"), out)
    assert result.records == result.learned == 300 and not result.refused


def test_live_runs_refuse_other_world_kinds_naming_where_they_run(client: TestClient) -> None:
    response = client.post("/api/runs", json=stream_spec())
    assert response.status_code == 422
    [problem] = response.json()["detail"]
    assert problem["loc"] == ["body", "world", "kind"] and "POST /api/streams" in problem["msg"]


def test_the_strip_chart_of_a_log(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    figure = tmp_path / "strip.png"
    args = ["run", str(ROOT / "scenarios" / "mountaincar-log.toml"), "--log",
            str(ROOT / "examples" / "data" / "mountaincar-pump.csv"), "--quiet", "--strip", str(figure)]  # fmt: skip
    assert horde_main([*args, "--strip-demons", "position_g0.9,velocity_g0.5"]) == 0
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert horde_main([*args, "--strip-demons", "nobody"]) == 2
    assert "--strip-demons: unknown demon 'nobody'" in capsys.readouterr().err


def write_parquet(csv_log: Path, path: Path, bad_rows: dict[int, dict[str, Any]] | None = None) -> None:
    """The CSV log's records as a Parquet file (typed columns), with some cells replaced (None: a null)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    with csv_log.open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    for index, cells in (bad_rows or {}).items():
        rows[index].update(cells)
    columns = {
        name: [
            None if row[name] is None else (int(row[name]) if name == "action" else float(row[name])) for row in rows
        ]
        for name in rows[0]
    }
    pq.write_table(pa.table(columns), path, row_group_size=700)  # several row groups: read in batches


def test_a_parquet_log_learns_as_its_csv_log_does(tmp_path: Path) -> None:
    spec = RunSpec.model_validate(stream_spec())
    log = tmp_path / "log.csv"
    write_log(log, 2_500, seed=3)
    parquet = tmp_path / "log.parquet"
    write_parquet(log, parquet)
    from_csv, from_parquet = learn_log(spec, log), learn_log(spec, parquet)
    assert from_parquet.records == from_parquet.learned == 2_500 and not from_parquet.refused
    assert [d.prediction for d in from_parquet.demons] == [d.prediction for d in from_csv.demons]
    assert [d.mean_return for d in from_parquet.demons] == [d.mean_return for d in from_csv.demons]


def test_a_parquet_log_with_bad_rows_names_file_row_and_field(tmp_path: Path) -> None:
    spec = RunSpec.model_validate(stream_spec())
    log = tmp_path / "log.csv"
    write_log(log, 40)
    parquet = tmp_path / "log.parquet"
    write_parquet(log, parquet, {4: {"heat": None}, 9: {"action": "7"}})
    result = learn_log(spec, parquet)
    assert (result.records, result.learned) == (40, 38)
    assert [(r.index, r.field) for r in result.refused] == [
        (5, f"{parquet}:5: observation.heat"),
        (10, f"{parquet}:10: action"),
    ], result.refused


def test_a_file_that_is_no_parquet_is_named(tmp_path: Path) -> None:
    spec = RunSpec.model_validate(stream_spec())
    fake = tmp_path / "log.parquet"
    fake.write_text("light,wheel,heat,action\n0.5,0,30,1\n")
    with pytest.raises(ValueError, match=r"log\.parquet: not a Parquet file"):
        learn_log(spec, fake)


def test_a_stream_run_has_a_demon_table_equal_to_its_learner(client: TestClient) -> None:
    run = client.post("/api/streams", json=stream_spec()).json()["id"]
    rng = np.random.default_rng(3)
    records = [{"observation": [rng.random(), rng.uniform(-1, 1), 30.0], "action": int(rng.integers(3))}
               for _ in range(300)]  # fmt: skip
    pushed = client.post(f"/api/streams/{run}/records", json={"records": records}).json()
    table = client.get(f"/api/streams/{run}/demons").json()
    assert [d["name"] for d in table] == pushed["demons"]
    # The table's predictions are the learner's after the last record; every demon has its error measures.
    assert {d["name"]: d["prediction"] for d in table} == pushed["predictions"]
    assert all(d["metrics"]["rupee"] is not None and d["metrics"]["ude"] is not None for d in table)
    assert all(not d["metrics"]["diverged"] and d["metrics"]["step_size"] > 0 for d in table)
    assert next(d for d in table if d["name"] == "light_if_left")["spec"]["learner"] == "gq"
    assert client.get("/api/streams/nope/demons").status_code == 404


def test_a_stream_run_exported_and_imported_learns_the_next_records_exactly_alike(client: TestClient) -> None:
    run = client.post("/api/streams", json=stream_spec()).json()["id"]
    rng = np.random.default_rng(4)

    def records(n: int) -> list[dict[str, Any]]:
        return [{"observation": [rng.random(), rng.uniform(-1, 1), 30.0], "action": int(rng.integers(3)),
                 "behaviour_probabilities": [0.5, 0.25, 0.25]} for _ in range(n)]  # fmt: skip

    client.post(f"/api/streams/{run}/records", json={"records": records(250)})
    snapshot = client.get(f"/api/streams/{run}/snapshot").json()
    assert snapshot["received"] == snapshot["learned"] == 250 and snapshot["pending_action"] in (0, 1, 2)
    twin = client.post("/api/streams/import", json=snapshot)
    assert twin.status_code == 201, twin.text
    assert twin.json()["predictions"] == client.get(f"/api/streams/{run}").json()["predictions"]
    more = records(120)
    a = client.post(f"/api/streams/{run}/records", json={"records": more}).json()
    b = client.post(f"/api/streams/{twin.json()['id']}/records", json={"records": more}).json()
    assert a["learned"] == b["learned"] == 370
    assert a["predictions"] == b["predictions"]  # the pending transition and the traces came along
    # A fresh run fed only the 120 records differs: the import carried the learning over.
    fresh = client.post("/api/streams", json=stream_spec()).json()["id"]
    c = client.post(f"/api/streams/{fresh}/records", json={"records": more}).json()
    assert c["predictions"] != a["predictions"]
    bad = {**snapshot, "pending_action": 7}
    assert client.post("/api/streams/import", json=bad).json()["detail"][0]["loc"] == ["body", "pending_action"]
