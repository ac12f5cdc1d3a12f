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

import statistics
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path

import httpx
import pytest
from benchmarks.reproducers import HealthPoller, attacks, send

from horde.server import Settings

from .helpers import make_spec
from .test_restart import server

pytestmark = pytest.mark.serial  # a bound of 100 ms: alone

HEALTH_LIMIT = 0.1  # seconds: the median check
STALL = 1.0  # seconds: no check may take longer
PRIORITY = -5  # niceness of the server and the poller, where allowed


def can_raise_priority() -> bool:
    """Whether this process may start processes at a negative niceness (root, or CAP_SYS_NICE)."""
    probe = subprocess.run([sys.executable, "-c", f"import os; os.nice({PRIORITY})"], capture_output=True)
    return probe.returncode == 0


@pytest.mark.slow
def test_health_answers_within_100_ms_while_bad_requests_run(tmp_path: Path) -> None:
    nice = PRIORITY if can_raise_priority() else 0
    with server(tmp_path / "data", tmp_path / "server.log", snapshot_every=2.0, nice=nice) as (_, client):
        run = client.post("/api/runs", json=make_spec()).json()["id"]
        # Warm up the routes (first imports, first compilation of validators) before measuring.
        client.get("/api/health")
        client.post("/api/runs", json=make_spec()).raise_for_status()

        poller = HealthPoller(str(client.base_url))
        statuses: dict[str, set[int]] = {}

        def attack(name: str, request: Callable[[httpx.Client], httpx.Response]) -> None:
            statuses[name] = send(str(client.base_url), request)

        bad_requests = attacks(run, make_spec(), Settings().max_demons)
        threads = [threading.Thread(target=attack, args=item, daemon=True) for item in bad_requests]
        began = time.monotonic()
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join(timeout=120)
            assert not thread.is_alive(), "a bad request hung"
        seconds = time.monotonic() - began
        time.sleep(0.3)
        baseline, latencies = poller.stop()

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
