"""How long `/api/health` takes while each bad request of issue 10 runs, alone and all at once.

Starts the server (`python -m horde.server`, with its viser view) on a free loopback port with a temporary
data directory, at niceness -5 where allowed (as the test does: the machine's other work then delays it
less). For each reproducer of `reproducers.attacks` alone, then for all of them at once, a poller process
reads `/api/health` every 10 ms while the requests are sent `--rounds` times; it prints each case's number
of checks, median and worst answer, and the worst of the idle server measured just before, and the statuses
the requests got (4xx, or 201 for the valid chain of 1,000 demons). The goal is every check within 100 ms.

Run: `python -m benchmarks.bench_health [--rounds 3] [--repeat 3] [--json PATH]`.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path

import httpx

from benchmarks.bench_stream import free_port
from benchmarks.reproducers import Attack, HealthPoller, attacks, send
from horde.scenarios import find_scenario
from horde.server import Settings

PRIORITY = -5


def start_server(port: int, data: str) -> subprocess.Popen[bytes]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("HORDE_")}
    command = [sys.executable, "-m", "horde.server", "--host", "127.0.0.1", "--port", str(port), "--data", data]
    try:
        return subprocess.Popen(
            [*command, "--log-level", "warning"],
            env=env,
            stdout=subprocess.DEVNULL,
            preexec_fn=lambda: os.nice(PRIORITY),
        )
    except subprocess.SubprocessError:  # not allowed to raise the priority here
        return subprocess.Popen([*command, "--log-level", "warning"], env=env, stdout=subprocess.DEVNULL)


def wait_healthy(url: str, timeout: float = 120.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            if httpx.get(url + "/api/health").status_code == 200:
                return
        except httpx.TransportError:
            pass
        time.sleep(0.1)
    raise RuntimeError("the server did not start")


def measure(url: str, cases: list[Attack], rounds: int) -> dict[str, object]:
    """Send `cases` at once (each on its own thread) while the poller runs; its figures in milliseconds."""
    poller = HealthPoller(url, idle_seconds=2.0)
    statuses: dict[str, list[int]] = {}

    def one(name: str, request: Callable[[httpx.Client], httpx.Response]) -> None:
        statuses[name] = sorted(send(url, request, rounds))

    threads = [threading.Thread(target=one, args=case, daemon=True) for case in cases]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=300)
    time.sleep(0.2)
    idle, busy = poller.stop()
    return {
        "checks": len(busy),
        "median_ms": 1000 * statistics.median(busy),
        "worst_ms": 1000 * max(busy),
        "over_100_ms": sum(latency > 0.1 for latency in busy),
        "idle_worst_ms": 1000 * max(idle),
        "statuses": statuses,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3, help="times each request is sent in one case")
    parser.add_argument("--repeat", type=int, default=3, help="times the all-at-once case is measured")
    parser.add_argument("--json", type=Path, help="write the figures here as JSON")
    args = parser.parse_args(argv)
    spec = find_scenario("experiment1").model_dump(mode="json", by_alias=True, exclude_none=True)
    port = free_port()
    url = f"http://127.0.0.1:{port}"
    results: list[dict[str, object]] = []
    with tempfile.TemporaryDirectory() as data:
        server = start_server(port, data)
        try:
            wait_healthy(url)
            run = httpx.post(url + "/api/runs", json=spec, timeout=60).json()["id"]
            httpx.post(url + "/api/runs", json=spec, timeout=60).raise_for_status()  # warm the routes
            cases = attacks(run, spec, Settings().max_demons)
            print(f"{'case':<24} {'checks':>6} {'median ms':>10} {'worst ms':>9} {'>100 ms':>8} {'idle worst':>10}")
            plan = [(case[0], [case]) for case in cases]
            plan += [(f"all at once ({i + 1})", cases) for i in range(args.repeat)]
            for name, chosen in plan:
                row = {"case": name, **measure(url, chosen, args.rounds)}
                results.append(row)
                print(
                    f"{name:<24} {row['checks']:>6} {row['median_ms']:>10.1f} {row['worst_ms']:>9.1f} "
                    f"{row['over_100_ms']:>8} {row['idle_worst_ms']:>10.1f}",
                    flush=True,
                )
        finally:
            server.kill()
            server.wait(timeout=30)
    alone = [r for r in results if not str(r["case"]).startswith("all at once")]
    print(f"worst of any reproducer alone: {max(float(str(r['worst_ms'])) for r in alone):.1f} ms")
    if args.json:
        args.json.write_text(json.dumps(results, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
