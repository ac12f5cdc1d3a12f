"""The phase plane: a demon's values over two sensors equal its predictions there; the scene; the REST route."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

with warnings.catch_warnings():
    warnings.filterwarnings("ignore", message=".*install `httpx2`")
    from fastapi.testclient import TestClient

from tests.worlds.test_streams import stream_spec, write_log

from horde.core.learner import Learner
from horde.server import Settings, create_app
from horde.spec import RunSpec
from horde.view.phase_plane import PLANE_SIZE, phase_plane_nodes, to_plane
from horde.worlds.phase_plane import Axis, axis_of, phase_plane


def learned_loop(tmp_path) -> tuple[Learner, np.ndarray]:  # type: ignore[no-untyped-def]
    from horde.worlds.records import RecordLearner, read_log

    spec = RunSpec.model_validate(stream_spec())
    learner = RecordLearner(spec)
    log = tmp_path / "log.csv"
    write_log(log, 3000)
    for records, _ in read_log(log, learner.world):
        learner.learn(records)
        last = records.observations[-1]
    return learner.loop, last


def test_the_value_map_is_the_demons_prediction_at_each_cell(tmp_path) -> None:  # type: ignore[no-untyped-def]
    loop, held = learned_loop(tmp_path)
    horde = loop.horde
    x, y = axis_of(horde, "light"), axis_of(horde, "wheel")
    assert (x.low, x.high, y.low, y.high) == (0.0, 1.0, -1.0, 1.0)
    values = phase_plane(horde, loop.horde_state(), "wheel_g0.9", x, y, held, resolution=5)
    assert values.shape == (5, 5) and np.ptp(values) > 0
    for j, i in [(0, 0), (2, 3), (4, 1)]:
        sensors = held.copy()
        sensors[0], sensors[1] = x.centres(5)[i], y.centres(5)[j]
        loop.observe(sensors)  # the engine's own prediction there (observing reads the weights, frozen)
        assert values[j, i] == pytest.approx(loop.prediction()[horde.index["wheel_g0.9"]], abs=1e-12)


def test_the_scene_puts_the_trail_on_the_plane() -> None:
    x, y = Axis("position", -1.2, 0.6), Axis("velocity", -0.07, 0.07)
    trail = np.array([[-1.2, -0.07], [-0.3, 0.0], [0.6, 0.07]])
    nodes = {n.name: n for n in phase_plane_nodes(x, y, "goal", np.arange(16.0).reshape(4, 4), trail)}
    half = PLANE_SIZE / 2
    np.testing.assert_allclose(to_plane(x, y, trail[:, 0], trail[:, 1])[:, :2], [[-half, -half], [0, 0], [half, half]])
    assert nodes["/phase/trail"].points is not None and nodes["/phase/trail"].points.shape == (2, 2, 3)
    assert nodes["/phase/agent"].position[:2] == pytest.approx((PLANE_SIZE / 2, PLANE_SIZE / 2))
    image = nodes["/phase/map"].image
    assert image is not None and image.shape[2] == 4
    assert tuple(image[0, 0, :3]) != tuple(image[-1, -1, :3]), "the lowest and highest values differ in colour"
    assert "position [-1.2, 0.6]" in nodes["/phase/x_label"].text


def test_the_phase_plane_route(tmp_path) -> None:  # type: ignore[no-untyped-def]
    with TestClient(create_app(Settings(data=tmp_path / "d", token=None, snapshot_every=3600.0))) as client:
        run = client.post("/api/streams", json=stream_spec()).json()
        records = [{"observation": [0.1 * k % 1, 0.0, 30.0], "action": k % 3} for k in range(50)]
        assert client.post(f"/api/streams/{run['id']}/records", json={"records": records}).status_code == 200
        url = f"/api/streams/{run['id']}/phase-plane"
        body = client.get(url, params={"demon": "light_g0.5", "x": "light", "y": "heat", "resolution": 8}).json()
        assert len(body["values"]) == 8 and len(body["values"][0]) == 8 and len(body["trail"]) == 50
        assert body["x"] == {"sensor": "light", "low": 0.0, "high": 1.0}
        bad = client.get(url, params={"demon": "light_g0.5", "x": "lux", "y": "heat"})
        assert bad.status_code == 422 and bad.json()["detail"][0]["loc"] == ["query", "x"]
        bad = client.get(url, params={"demon": "nobody", "x": "light", "y": "heat"})
        assert bad.status_code == 422 and bad.json()["detail"][0]["loc"] == ["query", "demon"]
