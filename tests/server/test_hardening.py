"""The reproducers of issue 10 (1-5) as tests: every bad request is a small 4xx naming the field, never a 500.

Non-finite numbers (NaN, Infinity, 1e999 as JSON writes them), an expression nested 300 deep, bodies
larger than the limit, a chain of 1,000 demons, speeds far below or above the documented range.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

from horde.server import Settings, create_app
from horde.server.guard import MAX_ERRORS, MAX_JSON_DEPTH, json_problem, validation_body
from horde.spec import MAX_EXPR_DEPTH, MAX_HZ, MIN_HZ

from .helpers import WORLD, make_spec, wait_for

NON_FINITE = ["NaN", "Infinity", "-Infinity", "1e999"]


def raw(client: TestClient, method: str, path: str, text: str, **kwargs: Any) -> Any:
    """Send `text` as a JSON body verbatim (json.dumps would refuse NaN or write it differently)."""
    return client.request(method, path, content=text, headers={"content-type": "application/json"}, **kwargs)


def problem_at(response: Any, *loc: str | int) -> dict[str, Any]:
    """The 422 problem whose location ends with `loc`; the body must stay small and hold no inputs."""
    assert response.status_code == 422, response.text
    assert len(response.content) < 20_000, len(response.content)
    detail = response.json()["detail"]
    assert all(set(p) == {"loc", "msg", "type"} for p in detail), detail
    found = [p for p in detail if tuple(p["loc"][-len(loc) :]) == loc]
    assert found, f"no problem at {loc}: {detail}"
    return found[0]


def with_value(body: str, placeholder: str, number: str) -> str:
    return body.replace(f'"{placeholder}"', number)


def run_body(**changes: Any) -> str:
    return json.dumps(make_spec(**changes))


# (method, path, body with a "X" where the number goes, the location that must be named)
CASES: list[tuple[str, str, Callable[[str], str], tuple[str | int, ...]]] = [
    ("POST", "/api/runs", lambda _: json.dumps({**make_spec(), "seed": "X"}), ("seed",)),
    ("POST", "/api/runs", lambda _: run_body(world={**WORLD, "width": "X"}), ("world", "width")),
    ("POST", "/api/runs", lambda _: run_body(world={**WORLD, "start": [0, "X"]}), ("world", "start", 1)),
    (
        "POST",
        "/api/runs",
        lambda _: run_body(world={**WORLD, "regions": [{"name": "z", "kind": "zone", "rect": [0, 0, "X", 1]}]}),
        ("world", "regions", 0, "rect", 2),
    ),
    ("POST", "/api/runs", lambda _: json.dumps({"scenario": "experiment1", "seed": "X"}), ("seed",)),
    ("POST", "/api/runs", lambda _: json.dumps({"scenario": "experiment1", "world": {"width": "X"}}), ("width",)),
    ("PUT", "/api/worlds/room", lambda _: json.dumps({**WORLD, "name": "room", "height": "X"}), ("height",)),
    ("PATCH", "/api/runs/{run}", lambda _: json.dumps({"hz": "X"}), ("hz",)),
    ("POST", "/api/runs/{run}/step", lambda _: json.dumps({"steps": "X"}), ("steps",)),
    ("POST", "/api/runs/{run}/evaluate", lambda _: json.dumps({"demon": "steps", "from": [0, "X"]}), ("from", 1)),
    ("POST", "/api/runs/{run}/demons", lambda _: json.dumps({"name": "new", "alpha": "X"}), ("alpha",)),
    ("POST", "/api/runs/{run}/demons", lambda _: json.dumps({"name": "new", "cumulant": "X"}), ("cumulant", "float")),
    ("POST", "/api/view", lambda _: json.dumps({"run": "X"}), ("run",)),
    ("POST", "/api/protocols", lambda _: json.dumps({"scenario": "experiment1", "seed": "X"}), ("seed",)),
]


@pytest.mark.parametrize("number", NON_FINITE)
def test_non_finite_numbers_are_422_naming_the_field(
    client: TestClient, create_run: Callable[..., str], number: str
) -> None:
    run = create_run()
    client.put("/api/worlds/room", json={**WORLD, "name": "room"})
    for method, path, body, loc in CASES:
        response = raw(client, method, path.format(run=run), with_value(body(""), "X", number))
        problem = problem_at(response, *loc)
        assert number.lstrip("-") not in response.text and problem["type"], response.text
    assert client.get(f"/api/runs/{run}").json()["status"] != "failed"


def test_non_finite_query_speed_is_422(client: TestClient) -> None:
    for hz in ("nan", "inf", "1e999", "1e-300", "0"):
        response = client.post("/api/runs", json=make_spec(), params={"hz": hz})
        problem_at(response, "query", "hz")


def test_a_deeply_nested_expression_is_a_small_fast_422(client: TestClient, create_run: Callable[..., str]) -> None:
    run = create_run()
    expr: Any = 1
    for _ in range(300):
        expr = {"add": [expr, 1]}
    began = time.perf_counter()
    response = client.post(f"/api/runs/{run}/demons", json={"name": "deep", "cumulant": expr})
    elapsed = time.perf_counter() - began
    problem = problem_at(response, *(["body", "cumulant"] + ["add", 0] * (MAX_JSON_DEPTH // 2 - 1))[-2:])
    assert problem["loc"][:2] == ["body", "cumulant"] and "deep" in problem["msg"]
    assert elapsed < 1.0, f"the 422 took {elapsed:.2f} s"

    # Within the JSON limit but beyond the expression limit: the spec names the field.
    expr = 1
    for _ in range(MAX_EXPR_DEPTH + 1):
        expr = {"mul": [expr, 1]}
    problem = problem_at(client.post(f"/api/runs/{run}/demons", json={"name": "deep", "outcome": expr}), "outcome")
    assert f"more than {MAX_EXPR_DEPTH}" in problem["msg"]


def test_many_errors_are_truncated_and_inputs_left_out() -> None:
    long = "x" * 10_000
    errors = [{"loc": ("body", "demons", i), "msg": long, "type": "t", "input": long} for i in range(500)]
    detail = json.loads(validation_body(errors))["detail"]
    assert len(detail) == MAX_ERRORS + 1 and "480 more" in detail[-1]["msg"]
    assert all("input" not in p and len(p["msg"]) <= 300 for p in detail)


def test_json_problem_is_iterative_and_names_the_place() -> None:
    deep: Any = 0
    for _ in range(100_000):  # far beyond Python's recursion limit
        deep = [deep]
    problem = json_problem({"a": deep})
    assert problem is not None and problem["loc"][:3] == ["body", "a", 0] and problem["type"] == "too_deep"
    assert json_problem({"a": list(range(30_000))}) == {
        "loc": ["body", "a"],
        "msg": "more than 20000 items",
        "type": "too_wide",
    }
    assert json_problem(make_spec()) is None


@pytest.fixture
def small_client(tmp_path: Path) -> Iterator[TestClient]:
    settings = Settings(data=tmp_path / "data", token=None, snapshot_every=3600.0, max_body=4096)
    with TestClient(create_app(settings)) as test_client:
        yield test_client


def test_bodies_beyond_the_limit_are_413(small_client: TestClient) -> None:
    big = json.dumps({**make_spec(), "description": "x" * 5000})
    response = raw(small_client, "POST", "/api/runs", big)
    assert response.status_code == 413 and "4096 bytes" in response.json()["detail"]

    def chunks() -> Iterator[bytes]:  # no Content-Length: the limit holds while the body streams in
        for _ in range(100):
            yield b" " * 1000

    response = small_client.post("/api/runs", content=chunks(), headers={"content-type": "application/json"})
    assert response.status_code == 413
    assert small_client.post("/api/runs", json=make_spec()).status_code == 201


def test_a_chain_of_a_thousand_demons_runs(client: TestClient) -> None:
    chain = [
        {
            "name": f"d{i}",
            "learner": "td",
            "features": {"kind": "constant"},
            "cumulant": {"prediction": f"d{i + 1}"} if i < 997 else 1,
        }
        for i in range(998)
    ]
    spec = make_spec()
    spec["demons"] = spec["demons"] + chain
    response = client.post("/api/runs", json=spec)
    assert response.status_code == 201, response.text[:500]
    run = response.json()["id"]
    assert client.post(f"/api/runs/{run}/step", json={"steps": 5}).status_code == 200


@pytest.mark.parametrize("hz", [1e-12, 1e-300, 0.0, MAX_HZ * 1.001])
def test_speeds_outside_the_range_are_422(client: TestClient, create_run: Callable[..., str], hz: float) -> None:
    run = create_run()
    problem_at(client.patch(f"/api/runs/{run}", json={"hz": hz}), "hz")


def test_the_slowest_and_fastest_speeds_keep_the_run_alive(client: TestClient, create_run: Callable[..., str]) -> None:
    run = create_run()
    for hz in (MIN_HZ, MAX_HZ):
        assert client.patch(f"/api/runs/{run}", json={"hz": hz}).status_code == 200
        assert client.post(f"/api/runs/{run}/start").status_code == 200
        time.sleep(0.3)
        body = client.post(f"/api/runs/{run}/pause").json()
        assert body["status"] == "paused", body
    wait_for(client, run, "paused")


def test_at_most_a_few_requests_work_in_threads_at_once(client: TestClient, monkeypatch: pytest.MonkeyPatch) -> None:
    """A burst of large bodies is parsed by at most REQUEST_THREADS worker threads at once (with many
    threads busy, the event loop waits behind each of them for the GIL), and every request is answered."""
    import threading

    from horde.server import guard

    lock = threading.Lock()
    running, most = 0, 0
    check_json = guard._check_json

    def slow_check(body: bytes, max_demons: int | None) -> Any:
        nonlocal running, most
        with lock:
            running += 1
            most = max(most, running)
        time.sleep(0.2)
        with lock:
            running -= 1
        return check_json(body, max_demons)

    monkeypatch.setattr(guard, "_check_json", slow_check)
    body = json.dumps({**make_spec(), "description": "x" * guard.THREAD_BYTES})  # large: parsed in a thread
    statuses: list[int] = []

    def post() -> None:
        statuses.append(raw(client, "POST", "/api/runs", body).status_code)

    threads = [threading.Thread(target=post) for _ in range(3 * guard.REQUEST_THREADS)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=60)
    assert len(statuses) == len(threads), "a request was not answered"
    assert 2 <= most <= guard.REQUEST_THREADS, most
