"""A classroom on one server: 30 viewers of one live run while 10 student runs learn (issue 28, item 4).

Starts the server (`python -m horde.server`, with its viser view and a teacher's HORDE_TOKEN) on free loopback
ports with a temporary data directory. The teacher issues 10 student tokens; each student launches a run of
`experiment1` at full speed (protocol.episodes = 0), and the teacher launches one more, the viewed run. Then,
from this process, alternately without viewers and with them (A B A B A: the machine's background load
drifts, so the means are compared), it measures for `--seconds`:

- the viewed run's steps per second (and all eleven runs' together);
- `/api/health`'s answer time, asked every 50 ms (median and 99th percentile);
- under load, `--viewers` API stream clients (WS /api/runs/{id}/stream) and `--viewers` viser clients, each a
  dashboard tab's view (its own key, POST /api/view naming the viewed run) that reads every message viser
  sends it: messages per second each, and how many were dropped (closed by the server);
- the server's CPU seconds per wall second, and the load average.

The goal (issue 28): the viewed run keeps at least 0.8 of its speed without viewers, health's 99th percentile
under 100 ms, no client dropped. The server is stopped at the end.

Run: `python -m benchmarks.bench_classroom [--seconds 10] [--viewers 30] [--students 10] [--rounds 2]
[--json PATH]`.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import secrets
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import httpx
import msgspec.msgpack
import viser
from viser import _messages
from websockets.asyncio.client import connect

from benchmarks.bench_stream import Client, cpu_seconds, free_port, stream, wait_healthy

TEACHER_TOKEN = "teacher-" + secrets.token_hex(8)
CAMERA = _messages.ViewerCameraMessage(
    wxyz=(1.0, 0.0, 0.0, 0.0), position=(0.0, 0.0, 10.0), fov=1.0, near=0.01, far=1000.0,
    image_height=600, image_width=800, look_at=(0.0, 0.0, 0.0), up_direction=(0.0, 1.0, 0.0),
)  # fmt: skip
HEALTH_PERIOD = 0.05  # seconds between health checks


def start_server(port: int, viser_port: int, data: str) -> subprocess.Popen[bytes]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("HORDE_")}
    env["HORDE_TOKEN"] = TEACHER_TOKEN
    command = [sys.executable, "-m", "horde.server", "--host", "127.0.0.1", "--port", str(port), "--data", data,
               "--viser-port", str(viser_port), "--log-level", "warning"]  # fmt: skip
    return subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL)


@dataclass
class ViserClient:
    """One dashboard tab's viser client: its key, the messages it read, whether the server closed on it."""

    key: str
    messages: int = 0
    closed: list[str] = field(default_factory=list)


async def view(port: int, client: ViserClient, stop: asyncio.Event) -> None:
    """Connect as the viser client does (its subprotocol, then a camera message), read until `stop`."""
    url = f"ws://127.0.0.1:{port}/?viewer={client.key}"
    origin = f"http://127.0.0.1:{port}"
    async with connect(url, subprotocols=[f"viser-v{viser.__version__}"], origin=origin, max_size=2**26) as ws:  # type: ignore[list-item,arg-type]
        await ws.send(msgspec.msgpack.encode(CAMERA.as_serializable_dict()))
        while not stop.is_set():
            try:
                await asyncio.wait_for(ws.recv(), timeout=0.5)
            except TimeoutError:
                continue
            except Exception as exc:  # the server closed the view
                client.closed.append(repr(exc))
                return
            client.messages += 1


async def health_checks(http: httpx.AsyncClient, stop: asyncio.Event, latencies: list[float]) -> None:
    while not stop.is_set():
        began = time.perf_counter()
        response = await http.get("/api/health")
        latencies.append(time.perf_counter() - began if response.status_code == 200 else float("inf"))
        await asyncio.sleep(max(0.0, HEALTH_PERIOD - (time.perf_counter() - began)))


async def steps(http: httpx.AsyncClient) -> dict[str, int]:
    return {r["id"]: int(r["step"]) for r in (await http.get("/api/runs")).json()}


@dataclass
class Phase:
    viewers: bool
    viewed_rate: float
    total_rate: float
    health: list[float]
    cpu: float  # the API process's CPU seconds per wall second (the live view's thread included)
    learner_cpu: float  # the runs' workers' (niced processes under the API's fork server), beside it
    client_cpu: float  # this process's (the viewers' clients), per wall second
    load: float  # 1-minute load average at the end
    stream_rates: list[float] = field(default_factory=list)
    viser_rates: list[float] = field(default_factory=list)
    dropped: int = 0
    browsers: int = 0  # the live view's connected browsers, as the server counts them at the end
    frame_rate: float = 0.0  # the view's frames a second (each draws every browser's view), at the end


async def phase(http: httpx.AsyncClient, server: int, ports: tuple[int, int], viewed: str, loaded: bool,
                args: argparse.Namespace) -> Phase:  # fmt: skip
    port, viser_port = ports
    stop, health_stop = asyncio.Event(), asyncio.Event()
    streams = [Client(viewed) for _ in range(args.viewers if loaded else 0)]
    views = [ViserClient(secrets.token_hex(8)) for _ in range(args.viewers if loaded else 0)]
    tasks = [asyncio.create_task(stream(f"ws://127.0.0.1:{port}/api/runs/{viewed}/stream", c, stop)) for c in streams]
    for client in views:  # each tab tells the server which run its own view shows, as the dashboard does
        (await http.post("/api/view", json={"viewer": client.key, "run": viewed})).raise_for_status()
        tasks.append(asyncio.create_task(view(viser_port, client, stop)))
    if loaded:
        await asyncio.sleep(args.settle)  # all connected, their panels built, streaming
    latencies: list[float] = []
    checker = asyncio.create_task(health_checks(http, health_stop, latencies))
    counted = [c.messages for c in streams], [c.messages for c in views]
    cpu_began, began, before = cpu_seconds(server), time.monotonic(), await steps(http)
    learner_began, client_began = cpu_seconds(server, learners_only=True), time.process_time()
    await asyncio.sleep(args.seconds)
    after, wall = await steps(http), time.monotonic() - began
    cpu = (cpu_seconds(server) - cpu_began) / wall
    learner_cpu = (cpu_seconds(server, learners_only=True) - learner_began) / wall
    client_cpu = (time.process_time() - client_began) / wall
    view_load = (await http.get("/api/view")).json()
    health_stop.set()
    await checker
    result = Phase(loaded, (after[viewed] - before[viewed]) / wall,
                   sum(after[r] - before[r] for r in before if r in after) / wall, latencies, cpu, learner_cpu,
                   client_cpu, os.getloadavg()[0],
                   [(c.messages - n) / wall for c, n in zip(streams, counted[0], strict=True)],
                   [(c.messages - n) / wall for c, n in zip(views, counted[1], strict=True)],
                   sum(1 for c in [*streams, *views] if c.closed), view_load["browsers"],
                   view_load["frame_rate"])  # fmt: skip
    stop.set()
    await asyncio.gather(*tasks, return_exceptions=True)
    if loaded:
        await asyncio.sleep(2.0)  # all gone
    return result


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))] if ordered else float("nan")


async def bench(args: argparse.Namespace) -> dict[str, Any]:
    port, viser_port = free_port(), free_port()
    phases: list[Phase] = []
    with tempfile.TemporaryDirectory(prefix="horde-classroom-") as data:
        server = start_server(port, viser_port, data)
        teacher = {"Authorization": f"Bearer {TEACHER_TOKEN}"}
        try:
            async with httpx.AsyncClient(base_url=f"http://127.0.0.1:{port}", timeout=60.0) as http:
                await wait_healthy(http)
                body = {"scenario": "experiment1", "protocol": {"episodes": 0}}
                for k in range(args.students):
                    token = (await http.post("/api/tokens", json={"role": "student", "name": f"student{k}"},
                                             headers=teacher)).json()["token"]  # fmt: skip
                    student = {"Authorization": f"Bearer {token}"}
                    created = await http.post("/api/runs", json={**body, "seed": k, "name": f"student{k}"},
                                              params={"start": "true"}, headers=student)  # fmt: skip
                    created.raise_for_status()
                created = await http.post("/api/runs", json={**body, "seed": 99, "name": "viewed"},
                                          params={"start": "true"}, headers=teacher)  # fmt: skip
                created.raise_for_status()
                viewed = created.json()["id"]
                await asyncio.sleep(args.warmup)
                for k in range(2 * args.rounds + 1):
                    phases.append(await phase(http, server.pid, (port, viser_port), viewed, k % 2 == 1, args))
                    p = phases[-1]
                    what = f"with {args.viewers} + {args.viewers} viewers" if p.viewers else "without viewers"
                    print(f"  {what:28} viewed run {p.viewed_rate:8,.0f} steps/s, all {p.total_rate:9,.0f}; "
                          f"health p99 {1000 * percentile(p.health, 0.99):6.1f} ms; API process CPU {p.cpu:.2f}/s "
                          f"(workers {p.learner_cpu:.2f}), clients' {p.client_cpu:.2f}/s; "
                          f"load {p.load:.1f}; view {p.browsers} browsers at {p.frame_rate:.1f} frames/s",
                          flush=True)  # fmt: skip
        finally:
            server.terminate()
            server.wait(timeout=30)
    alone = [p for p in phases if not p.viewers]
    viewed_phases = [p for p in phases if p.viewers]

    def mean(values: list[float]) -> float:
        return sum(values) / len(values)

    health_alone = [x for p in alone for x in p.health]
    health_viewed = [x for p in viewed_phases for x in p.health]
    stream_rates = [x for p in viewed_phases for x in p.stream_rates]
    viser_rates = [x for p in viewed_phases for x in p.viser_rates]
    result = {
        "seconds": args.seconds,
        "rounds": args.rounds,
        "students": args.students,
        "viewers": args.viewers,
        "viewed_steps_per_s": {
            "alone": mean([p.viewed_rate for p in alone]),
            "viewed": mean([p.viewed_rate for p in viewed_phases]),
        },
        "all_steps_per_s": {
            "alone": mean([p.total_rate for p in alone]),
            "viewed": mean([p.total_rate for p in viewed_phases]),
        },
        "health_ms": {
            "alone": {"median": 1000 * statistics.median(health_alone), "p99": 1000 * percentile(health_alone, 0.99)},
            "viewed": {
                "median": 1000 * statistics.median(health_viewed),
                "p99": 1000 * percentile(health_viewed, 0.99),
            },
        },
        "server_cpu_per_s": {"alone": mean([p.cpu for p in alone]), "viewed": mean([p.cpu for p in viewed_phases])},
        "learner_cpu_per_s": {
            "alone": mean([p.learner_cpu for p in alone]),
            "viewed": mean([p.learner_cpu for p in viewed_phases]),
        },
        "client_cpu_per_s": {"viewed": mean([p.client_cpu for p in viewed_phases])},
        "load_average": [p.load for p in phases],
        "stream_messages_per_s": {"min": min(stream_rates), "mean": mean(stream_rates)},
        "viser_messages_per_s": {"min": min(viser_rates), "mean": mean(viser_rates)},
        "dropped": sum(p.dropped for p in viewed_phases),
        "view_browsers": [p.browsers for p in viewed_phases],
        "view_frames_per_s": [p.frame_rate for p in viewed_phases],
    }
    result["ratio"] = result["viewed_steps_per_s"]["viewed"] / result["viewed_steps_per_s"]["alone"]
    return result


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.bench_classroom", description=__doc__)
    parser.add_argument("--seconds", type=float, default=10.0, help="length of each measurement")
    parser.add_argument("--viewers", type=int, default=30, help="API stream clients, and as many viser clients")
    parser.add_argument("--students", type=int, default=10, help="student runs learning beside the viewed one")
    parser.add_argument("--rounds", type=int, default=2, help="measurements with viewers (one more without)")
    parser.add_argument("--warmup", type=float, default=10.0, help="seconds of learning before the first")
    parser.add_argument("--settle", type=float, default=5.0, help="seconds for the viewers to connect")
    parser.add_argument("--json", type=Path, help="write the figures here")
    args = parser.parse_args(argv)
    result = asyncio.run(bench(args))
    rates = result["viewed_steps_per_s"]
    print(f"viewed run: {rates['alone']:,.0f} steps/s alone, "
          f"{rates['viewed']:,.0f} viewed: ratio {result['ratio']:.3f} (goal >= 0.8)")  # fmt: skip
    print(f"health: p99 {result['health_ms']['alone']['p99']:.1f} ms alone, "
          f"{result['health_ms']['viewed']['p99']:.1f} ms viewed (goal < 100 ms)")  # fmt: skip
    print(f"stream clients: min {result['stream_messages_per_s']['min']:.1f} messages/s; viser clients: min "
          f"{result['viser_messages_per_s']['min']:.1f} messages/s; dropped: {result['dropped']} (goal 0)")  # fmt: skip
    print(f"live view: {result['view_browsers']} browsers at {result['view_frames_per_s']} frames/s (each frame "
          "draws every browser's view)")  # fmt: skip
    print(f"the runs' workers' CPU per second: {result['learner_cpu_per_s']['alone']:.2f} alone, "
          f"{result['learner_cpu_per_s']['viewed']:.2f} viewed; the clients' process "
          f"{result['client_cpu_per_s']['viewed']:.2f} viewed")  # fmt: skip
    print(f"the API process's CPU per second: {result['server_cpu_per_s']['alone']:.2f} alone, "
          f"{result['server_cpu_per_s']['viewed']:.2f} viewed; load averages {result['load_average']}")  # fmt: skip
    if args.json is not None:
        args.json.write_text(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
