"""GET /api/streams and GET /api/streams/{id}/history: the strip chart's data, each prediction beside the
discounted return that followed it, checked against returns summed by hand."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

from horde.spec import RunSpec
from horde.worlds.records import RecordLearner
from sockets import receive_json
from stream_specs import LIGHT_WHEEL, nexting, robot, tiled


def spec() -> dict[str, Any]:
    return robot(tiled(LIGHT_WHEEL, tilings=2, tiles=4, size=64), nexting("light", 0.5), nexting("wheel", 0.0))


def records(n: int, start: int = 0) -> list[dict[str, Any]]:
    return [{"observation": [(0.37 * k) % 1, np.sin(k / 3.0)], "action": k % 2} for k in range(start, start + n)]


def by_hand(light: list[float], gamma: float) -> list[float | None]:
    """G_t = sum_{k >= 1} gamma^(k-1) light_{t+k}, None where the rest would weigh 1e-3 or more."""
    out: list[float | None] = []
    for t in range(len(light)):
        ahead = light[t + 1 :]
        weight = gamma ** len(ahead)
        out.append(sum(gamma**k * x for k, x in enumerate(ahead)) if weight < 1e-3 else None)
    return out


def test_the_history_puts_each_prediction_beside_the_return_that_followed(client: TestClient) -> None:
    run = client.post("/api/streams", json=spec()).json()
    assert [(s["id"], s["name"]) for s in client.get("/api/streams").json()] == [(run["id"], "robot")]
    url = f"/api/streams/{run['id']}"
    pushed = records(60)
    assert client.post(f"{url}/records", json={"records": pushed[:25]}).status_code == 200
    assert client.post(f"{url}/records", json={"records": pushed[25:]}).status_code == 200
    body = client.get(f"{url}/history", params={"sensors": "light", "demons": "light_g0.5,wheel_g0"}).json()
    assert body["records"] == list(range(60))
    light = [r["observation"][0] for r in pushed]
    assert body["sensors"]["light"] == pytest.approx(light)
    expected = by_hand(light, 0.5)
    assert expected[49] is not None and expected[50] is None  # 0.5^10 < 1e-3: the last 10 are not known yet
    assert body["returns"]["light_g0.5"][:50] == pytest.approx(expected[:50], abs=1e-12)
    assert body["returns"]["light_g0.5"][50:] == [None] * 10
    wheel = [r["observation"][1] for r in pushed]
    assert body["returns"]["wheel_g0"][:59] == pytest.approx(wheel[1:], abs=1e-12)  # gamma 0: the next reading
    # The predictions are those made at the time: the same records learned in one go give them.
    learner = RecordLearner(RunSpec.model_validate(spec()))
    checked, _ = learner.check(pushed)
    kept = learner.learn(checked, keep_predictions=True)
    assert kept is not None
    assert body["predictions"]["light_g0.5"] == pytest.approx(kept[:, 0].tolist(), abs=1e-12)
    assert body["predictions"]["wheel_g0"][-1] == pytest.approx(client.get(url).json()["predictions"]["wheel_g0"])
    last = client.get(f"{url}/history", params={"last": 5}).json()
    assert last["records"] == [55, 56, 57, 58, 59] and set(last["sensors"]) == {"light", "wheel"}


def test_a_refused_record_breaks_the_realised_returns_there(client: TestClient) -> None:
    url = f"/api/streams/{client.post('/api/streams', json=spec()).json()['id']}"
    good = records(40)
    with client.websocket_connect(f"{url}/records") as ws:
        receive_json(ws, "the hello")  # hello
        ws.send_json({"records": [*good[:20], {"observation": [0.5, float("nan")], "action": 0}, *good[20:]]})
        assert receive_json(ws, "the error for the NaN record")["type"] == "error"
        assert receive_json(ws, "the learned count")["learned"] == 40
    body = client.get(f"{url}/history", params={"demons": "light_g0.5"}).json()
    assert body["records"] == [*range(20), *range(21, 41)], "the refused record 20 is not in the history"
    light = [r["observation"][0] for r in good]
    before, after = by_hand(light[:20], 0.5), by_hand(light[20:], 0.5)  # each side of the gap on its own
    assert body["returns"]["light_g0.5"] == pytest.approx([*before, *after], abs=1e-12)


def test_bad_history_requests_name_the_field(client: TestClient) -> None:
    url = f"/api/streams/{client.post('/api/streams', json=spec()).json()['id']}"
    assert client.get("/api/streams/nobody/history").status_code == 404
    for params, field in [({"sensors": "lux"}, "sensors"), ({"demons": "nobody"}, "demons"),
                          ({"sensors": ","}, "sensors"), ({"last": 1}, "last"), ({"last": 10**6}, "last")]:  # fmt: skip
        response = client.get(f"{url}/history", params=params)
        assert response.status_code == 422, params
        assert response.json()["detail"][0]["loc"] == ["query", field]
    empty = client.get(f"{url}/history").json()  # nothing pushed yet: empty series, not an error
    assert empty["records"] == [] and empty["returns"]["light_g0.5"] == []


def test_the_ring_of_recent_records_keeps_the_newest_in_order() -> None:
    from horde.runs.stream_learning import RecentRecords

    ring = RecentRecords(5, sensors=1, demons=3)
    for start, n in [(0, 3), (3, 4), (7, 1)]:  # wraps around twice
        rows = np.arange(start, start + n, dtype=float)
        ring.add(rows[:, None], np.stack([rows, 10 * rows, 100 * rows], axis=1), np.arange(start, start + n),
                 np.zeros(n, dtype=bool))  # fmt: skip
    observations, predictions, numbers, _ = ring.last(10, [2, 0])
    assert numbers.tolist() == [3, 4, 5, 6, 7] and observations[:, 0].tolist() == [3, 4, 5, 6, 7]
    assert predictions.tolist() == [[100 * k, k] for k in [3, 4, 5, 6, 7]]  # the demons asked, in that order
    big = np.arange(12, dtype=float)
    ring.add(big[:, None], np.zeros((12, 3)), np.arange(12), np.zeros(12, dtype=bool))  # more than it holds
    assert ring.last(2, [0])[2].tolist() == [10, 11]
