"""Every reproducer of issue 10 at once against a real server, while /api/health is polled: no bad request
may get a 5xx, and no request may stall the event loop (the 17 MB 422 once held it for 19 to 40 s).

What the test asserts is a stall, not a speed: the median check within 100 ms and none beyond one second
(speed is not asserted in tests on a shared machine). The figures it prints, and those in
docs/performance.md, are the measure of the 100 ms goal: on a quiet machine the worst check is tens of
milliseconds, with a rare one of 100 to 200 ms.

The server is a subprocess (`python -m horde.server`), so the event loop measured is the real one, and so
is the poller (the attackers' threads in this process would otherwise delay its clock readings). On a
machine busy with other work the operating system alone delays answers: the server and the poller run
at a higher priority (niceness -5, where the test may set it) than the machine's other work, and the
slowest answer of the idle server, measured just before, is printed beside the figures under attack.
"""

from __future__ import annotations

import json
import statistics
import subprocess
import sys
import textwrap
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest

from horde.server import Settings

from .helpers import make_spec
from .test_restart import server

HEALTH_LIMIT = 0.1  # seconds: the median check
STALL = 1.0  # seconds: no check may take longer
PRIORITY = -5  # niceness of the server and the poller, where allowed


def can_raise_priority() -> bool:
    """Whether this process may start processes at a negative niceness (root, or CAP_SYS_NICE)."""
    probe = subprocess.run([sys.executable, "-c", f"import os; os.nice({PRIORITY})"], capture_output=True)
    return probe.returncode == 0


ROUNDS = 3  # each bad request is sent this many times


def deep_expression(levels: int) -> Any:
    expr: Any = 1
    for _ in range(levels):
        expr = {"add": [expr, 1]}
    return expr


def chain(length: int) -> list[dict[str, Any]]:
    return [
        {
            "name": f"d{i}",
            "learner": "td",
            "features": {"kind": "constant"},
            "cumulant": {"prediction": f"d{i + 1}"} if i < length - 1 else 1,
        }
        for i in range(length)
    ]


def big_body() -> Iterator[bytes]:
    for _ in range(50):  # 50 MB, streamed without Content-Length
        yield b" " * 1_000_000


def attacks(run: str) -> list[tuple[str, Callable[[httpx.Client], httpx.Response]]]:
    json_headers = {"content-type": "application/json"}

    def raw(method: str, path: str, text: str) -> Callable[[httpx.Client], httpx.Response]:
        return lambda c: c.request(method, path, content=text, headers=json_headers)

    wide = make_spec(demons=make_spec()["demons"] + chain(998))
    # One demon past the server's limit: refused before validation, so its size costs the server nothing.
    over = Settings().max_demons + 1
    many = make_spec(
        demons=make_spec()["demons"] + [{"name": f"x{i}", "cumulant": {"mul": [1, 2]}} for i in range(over)]
    )
    return [
        (
            "deep expression",
            lambda c: c.post(f"/api/runs/{run}/demons", json={"name": "d", "cumulant": deep_expression(300)}),
        ),
        ("50 MB declared", lambda c: c.post("/api/runs", content=b" " * 50_000_000, headers=json_headers)),
        ("50 MB streamed", lambda c: c.post("/api/runs", content=big_body(), headers=json_headers)),
        ("NaN seed", raw("POST", "/api/runs", '{"scenario": "experiment1", "seed": NaN}')),
        ("1e999 width", raw("POST", "/api/runs", json.dumps(make_spec()).replace('"width": 500', '"width": 1e999'))),
        ("Infinity hz", raw("PATCH", f"/api/runs/{run}", '{"hz": Infinity}')),
        ("tiny hz", raw("PATCH", f"/api/runs/{run}", '{"hz": 1e-12}')),
        ("NaN steps", raw("POST", f"/api/runs/{run}/step", '{"steps": NaN}')),
        ("NaN from", raw("POST", f"/api/runs/{run}/evaluate", '{"demon": "steps", "from": [0, NaN]}')),
        ("NaN alpha", raw("POST", f"/api/runs/{run}/demons", '{"name": "n", "alpha": NaN}')),
        ("NaN view", raw("POST", "/api/view", '{"run": NaN}')),
        ("1e999 protocol", raw("POST", "/api/protocols", '{"scenario": "experiment1", "seed": 1e999}')),
        ("chain of 1000", lambda c: c.post("/api/runs", json=wide)),
        ("demons past the limit", lambda c: c.post("/api/runs", json=many)),
    ]


# Polls /api/health every 10 ms: 3 s on the idle server (printed as the baseline's latencies), then until
# told to stop on stdin (printed as the latencies under attack).
POLLER = textwrap.dedent(
    """
    import json, sys, threading, time
    import httpx

    client = httpx.Client(base_url=sys.argv[1], timeout=30.0)

    def poll(stop):
        out = []
        while not stop():
            began = time.perf_counter()
            assert client.get("/api/health").status_code == 200
            out.append(time.perf_counter() - began)
            time.sleep(0.01)
        return out

    idle_end = time.monotonic() + 3.0
    idle = poll(lambda: time.monotonic() > idle_end)
    print("idle done", flush=True)
    stopped = threading.Event()
    threading.Thread(target=lambda: (sys.stdin.readline(), stopped.set()), daemon=True).start()
    busy = poll(stopped.is_set)
    print(json.dumps(idle))
    print(json.dumps(busy))
    """
)


@pytest.mark.slow
def test_health_answers_within_100_ms_while_bad_requests_run(tmp_path: Path) -> None:
    nice = PRIORITY if can_raise_priority() else 0
    with server(tmp_path / "data", tmp_path / "server.log", snapshot_every=2.0, nice=nice) as (_, client):
        run = client.post("/api/runs", json=make_spec()).json()["id"]
        # Warm up the routes (first imports, first compilation of validators) before measuring.
        client.get("/api/health")
        client.post("/api/runs", json=make_spec()).raise_for_status()

        poller = subprocess.Popen(
            [sys.executable, "-c", POLLER, str(client.base_url)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        assert poller.stdin is not None and poller.stdout is not None
        assert poller.stdout.readline().strip() == "idle done", "the poller did not start"

        statuses: dict[str, set[int]] = {}

        def attack(name: str, send: Callable[[httpx.Client], httpx.Response]) -> None:
            with httpx.Client(base_url=str(client.base_url), timeout=120.0) as attacker:
                for _ in range(ROUNDS):
                    try:
                        statuses.setdefault(name, set()).add(send(attacker).status_code)
                    except httpx.HTTPError:  # the server may close a 50 MB upload early, after its 413
                        statuses.setdefault(name, set()).add(413)

        threads = [threading.Thread(target=attack, args=item, daemon=True) for item in attacks(run)]
        began = time.monotonic()
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join(timeout=120)
            assert not thread.is_alive(), "a bad request hung"
        seconds = time.monotonic() - began
        time.sleep(0.3)
        out, _ = poller.communicate("stop\n", timeout=30)
        baseline, latencies = (json.loads(line) for line in out.splitlines()[:2])

    assert all(code < 500 for codes in statuses.values() for code in codes), statuses
    assert statuses["deep expression"] == {422} and statuses["50 MB declared"] == {413}, statuses
    assert statuses["demons past the limit"] == {422}, statuses
    assert statuses["chain of 1000"] == {201} or statuses["chain of 1000"] == {201, 409}, statuses
    worst, idle = max(latencies), max(baseline)
    print(
        f"{len(latencies)} health checks over {seconds:.1f} s of bad requests: median "
        f"{1000 * statistics.median(latencies):.1f} ms, max {1000 * worst:.1f} ms (idle: max {1000 * idle:.1f} ms)"
    )
    assert statistics.median(latencies) < HEALTH_LIMIT, f"median {statistics.median(latencies):.3f} s"
    assert worst < STALL, f"health took {1000 * worst:.0f} ms at worst: the event loop stalled"
