"""Every core (issue 23): 8 runs at full speed together against one run alone, on the server.

Each run learns in a worker process of its own, so runs spread over the machine's cores; in one process they
shared one GIL. Starts the server (`python -m horde.server --no-view`) on a free loopback port with a temporary
data directory; then alternates rounds (A, B, A, B, ...): A, one run of `--scenario` at full speed alone; B,
`--runs` such runs at once; each measured over `--seconds` seconds after a second to settle (the runs are
deleted after each round). It prints each round's steps a second (all runs together), the server's CPU
seconds (its process and its workers') per wall second, the load average, and the ratio of B's mean to A's
(goal at least 1.7 with 8 runs on 2 cores, on a quiet machine).

Run: `python -m benchmarks.bench_scaling [--runs 8] [--seconds 10] [--rounds 3] [--scenario experiment1]`.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import tempfile
import time
from pathlib import Path
from typing import Any

import httpx

from benchmarks.bench_load import start_server
from benchmarks.bench_stream import cpu_seconds, free_port, tree_cpu_seconds


def wait_healthy(client: httpx.Client, timeout: float = 120.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            if client.get("/api/health").status_code == 200:
                return
        except httpx.TransportError:
            pass
        time.sleep(0.1)
    raise RuntimeError("the server did not start")


def steps(client: httpx.Client, run_ids: list[str]) -> int:
    runs = {r["id"]: r for r in client.get("/api/runs").json()}
    return sum(int(runs[run_id]["step"]) for run_id in run_ids)


def round_(client: httpx.Client, pid: int, count: int, args: argparse.Namespace) -> dict[str, float]:
    """`count` runs at full speed: their steps a second together, and the server's CPU per wall second."""
    body = {"scenario": args.scenario, "protocol": {"episodes": 0}}
    run_ids = [client.post("/api/runs", json=body, params={"start": True}).json()["id"] for _ in range(count)]
    try:
        time.sleep(1.0)
        began, before = time.monotonic(), steps(client, run_ids)
        cpu, api = sum(tree_cpu_seconds(pid).values()), cpu_seconds(pid)
        time.sleep(args.seconds)
        elapsed = time.monotonic() - began
        rate = (steps(client, run_ids) - before) / elapsed
        used, api = (sum(tree_cpu_seconds(pid).values()) - cpu) / elapsed, (cpu_seconds(pid) - api) / elapsed
    finally:
        for run_id in run_ids:
            client.delete(f"/api/runs/{run_id}")
    return {"runs": count, "steps_per_s": rate, "cpu_per_wall_s": used, "api_cpu_per_wall_s": api,
            "steps_per_cpu_s": rate / max(used - api, 1e-9), "load_average": os.getloadavg()[0]}  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=8)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--rounds", type=int, default=3, help="pairs of rounds (one run alone, then all)")
    parser.add_argument("--scenario", default="experiment1")
    parser.add_argument("--json", metavar="PATH")
    args = parser.parse_args()
    port = free_port()
    rounds: list[dict[str, Any]] = []
    with tempfile.TemporaryDirectory() as data:
        server = start_server(port, data)
        try:
            with httpx.Client(base_url=f"http://127.0.0.1:{port}", timeout=120.0) as client:
                wait_healthy(client)
                round_(client, server.pid, 1, args)  # the workers' first start and kernels, unmeasured
                for _ in range(args.rounds):
                    for count in (1, args.runs):
                        result = round_(client, server.pid, count, args)
                        rounds.append(result)
                        print(f"{result['runs']} run(s): {result['steps_per_s']:,.0f} steps/s "
                              f"({result['steps_per_cpu_s']:,.0f} per worker CPU second), server "
                              f"{result['cpu_per_wall_s']:.2f} CPU s per s (the API process "
                              f"{result['api_cpu_per_wall_s']:.2f}), load average {result['load_average']:.2f}",
                              flush=True)  # fmt: skip
        finally:
            server.terminate()
            server.wait(120)
    alone = statistics.mean(r["steps_per_s"] for r in rounds if r["runs"] == 1)
    together = statistics.mean(r["steps_per_s"] for r in rounds if r["runs"] == args.runs)
    print(f"{args.runs} runs together: {together / alone:.2f} times one run alone ({together:,.0f} against "
          f"{alone:,.0f} steps/s; goal at least 1.7 with 8 runs on 2 cores)")  # fmt: skip
    if args.json:
        Path(args.json).write_text(json.dumps({"rounds": rounds, "ratio": together / alone}, indent=2) + "\n")


if __name__ == "__main__":
    main()
