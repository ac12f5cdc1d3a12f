"""The live view's cost per frame with many browsers of one run, in one process (no server, no HTTP).

Creates a run of `experiment1` stepping at 200 steps/s, a `LiveView` whose frames this script draws itself, and
`--clients` raw viser WebSocket clients, each a dashboard tab's view of that run (they read what the view sends,
in threads of their own). Then it draws `--frames` frames, 33 ms apart, and prints the view thread's CPU time
per frame (`time.thread_time`), its wall time, and the clients' messages. Alternate it with `--clients 0` for a
baseline. (The issue's load measurement, with a server and clients in another process, is bench_classroom.py.)

Run: `python -m benchmarks.bench_view_frames [--clients 30] [--frames 60]`.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from horde.runs.manager import RunManager
from horde.scenarios import find_scenario
from horde.view import ManagerSource

ROOT = Path(__file__).resolve().parents[1]


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.bench_view_frames", description=__doc__)
    parser.add_argument("--clients", type=int, default=30)
    parser.add_argument("--frames", type=int, default=60)
    args = parser.parse_args(argv)
    sys.path[:0] = [str(ROOT / "tests"), str(ROOT)]  # the tests' raw viser client
    from tests.view.viewers import RawClient, started_by_hand

    manager = RunManager()
    run = manager.create(find_scenario("experiment1"), hz=200.0, start=True).id
    source = ManagerSource(manager)
    view = started_by_hand(source)
    try:
        clients = [RawClient(view, f"dashboard-tab-{k:03d}") for k in range(args.clients)]
        for k in range(args.clients):
            view.show(f"dashboard-tab-{k:03d}", run)
        for _ in range(10):  # the panels built, the first scenes drawn
            view.refresh()
            time.sleep(0.033)
        received = sum(c.received for c in clients)
        cpu = wall = 0.0
        for _ in range(args.frames):
            began, began_cpu = time.perf_counter(), time.thread_time()
            view.refresh()
            cpu += time.thread_time() - began_cpu
            wall += time.perf_counter() - began
            time.sleep(0.033)
        messages = sum(c.received for c in clients) - received
        print(f"{args.clients} browsers of one run: the view's frame took {1000 * cpu / args.frames:.1f} ms of CPU, "
              f"{1000 * wall / args.frames:.1f} ms of wall time; {messages / max(1, args.clients) / args.frames:.2f} "
              "messages per browser and frame")  # fmt: skip
        for client in clients:
            client.close()
    finally:
        view.stop()
        manager.stop()


if __name__ == "__main__":
    main()
