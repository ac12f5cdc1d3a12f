"""The bad requests of issue 10 and a `/api/health` poller, shared by the test that sends them all at once
(`tests/server/test_health_under_attack.py`) and the benchmark that sends each alone (`bench_health.py`).

The poller is a separate process (`python -c POLLER URL`): in the sender's process, the senders' threads
would delay its clock readings.
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from collections.abc import Callable, Iterator
from typing import Any

import httpx

ROUNDS = 3  # each bad request is sent this many times
Attack = tuple[str, Callable[[httpx.Client], httpx.Response]]


def deep_expression(levels: int) -> Any:
    expr: Any = 1
    for _ in range(levels):
        expr = {"add": [expr, 1]}
    return expr


def chain(length: int) -> list[dict[str, Any]]:
    """Demons each reading the next one's prediction: a graph of `length` stages."""
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


def attacks(run: str, spec: dict[str, Any], max_demons: int) -> list[Attack]:
    """Every reproducer, against run `run`; `spec` is a valid run spec to spoil, `max_demons` the server's limit.

    The chain of 1,000 demons is valid (a 201); every other request is bad (a 4xx naming the field).
    """
    json_headers = {"content-type": "application/json"}

    def raw(method: str, path: str, text: str) -> Callable[[httpx.Client], httpx.Response]:
        return lambda c: c.request(method, path, content=text, headers=json_headers)

    wide = {**spec, "demons": spec["demons"] + chain(1000 - len(spec["demons"]))}
    # One demon past the server's limit: refused before validation, so its size costs the server nothing.
    many = {
        **spec,
        "demons": spec["demons"] + [{"name": f"x{i}", "cumulant": {"mul": [1, 2]}} for i in range(max_demons + 1)],
    }
    infinite_width = json.dumps({**spec, "world": {**spec["world"], "width": "WIDTH"}}).replace('"WIDTH"', "1e999")
    return [
        (
            "deep expression",
            lambda c: c.post(f"/api/runs/{run}/demons", json={"name": "d", "cumulant": deep_expression(300)}),
        ),
        ("50 MB declared", lambda c: c.post("/api/runs", content=b" " * 50_000_000, headers=json_headers)),
        ("50 MB streamed", lambda c: c.post("/api/runs", content=big_body(), headers=json_headers)),
        ("NaN seed", raw("POST", "/api/runs", '{"scenario": "experiment1", "seed": NaN}')),
        ("1e999 width", raw("POST", "/api/runs", infinite_width)),
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


def send(base_url: str, request: Callable[[httpx.Client], httpx.Response], rounds: int = ROUNDS) -> set[int]:
    """Send one reproducer `rounds` times on its own connection; the status codes it got."""
    statuses: set[int] = set()
    with httpx.Client(base_url=base_url, timeout=120.0) as client:
        for _ in range(rounds):
            try:
                statuses.add(request(client).status_code)
            except httpx.HTTPError:  # the server may close a 50 MB upload early, after its 413
                statuses.add(413)
    return statuses


# Polls /api/health every 10 ms: 3 s on the idle server (the baseline's latencies), then until told to
# stop on stdin (the latencies under attack).
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

    idle_end = time.monotonic() + float(sys.argv[2])
    idle = poll(lambda: time.monotonic() > idle_end)
    print("idle done", flush=True)
    stopped = threading.Event()
    threading.Thread(target=lambda: (sys.stdin.readline(), stopped.set()), daemon=True).start()
    busy = poll(stopped.is_set)
    print(json.dumps(idle))
    print(json.dumps(busy))
    """
)


class HealthPoller:
    """The poller process: started idle for `idle_seconds`, then polling until `stop()`.

    `stop()` returns (idle latencies, latencies since the idle phase), in seconds.
    """

    def __init__(self, base_url: str, idle_seconds: float = 3.0) -> None:
        self.process = subprocess.Popen(
            [sys.executable, "-c", POLLER, base_url, str(idle_seconds)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        assert self.process.stdout is not None
        started = self.process.stdout.readline().strip()
        if started != "idle done":
            self.process.kill()
            raise RuntimeError(f"the health poller did not start: {started!r}")

    def stop(self) -> tuple[list[float], list[float]]:
        out, _ = self.process.communicate("stop\n", timeout=30)
        idle, busy = (json.loads(line) for line in out.splitlines()[:2])
        return idle, busy
