"""Learning throughput with and without clients: WebSocket streams and REST pollers.

Starts the server (`python -m horde.server`) on a free loopback port with a temporary data directory,
creates `--runs` runs of `experiment1` that learn at full speed (protocol.episodes = 0), and measures
the steps per second of all of them together, alternately with no client and under load: 20 WebSocket
clients streaming the runs and 20 pollers reading GET /api/runs/{id}/state 10 times a second each
(without, with, without, with, without: the machine's background load drifts, so the means are
compared). Learning must not wait for clients, so the ratio of the two figures should stay near 1 (the
goal is at least 0.8). It prints both figures, their ratio, the server's CPU time per wall second in
each phase, the messages each client received per second, the pollers' answers and latencies, and
every failure (a dropped stream, a poll that was not 200). The server is stopped at the end.

Run: `python benchmarks/bench_stream.py [--seconds 10] [--clients 20] [--pollers 20] [--poll-hz 10]
[--runs 1] [--rounds 2]`.
"""

from __future__ import annotations

import argparse
import asyncio
import os
import socket
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field

import httpx
from websockets.asyncio.client import connect


@dataclass
class Client:
    """One streaming client: how many messages it got, and whether the server closed on it."""

    run_id: str
    messages: int = 0
    closed: list[str] = field(default_factory=list)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def start_server(port: int, data: str) -> subprocess.Popen[bytes]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("HORDE_")}
    command = [sys.executable, "-m", "horde.server", "--host", "127.0.0.1", "--port", str(port), "--data", data]
    command.append("--no-view")  # the viser view is measured by its own tests; here only the streams
    return subprocess.Popen([*command, "--log-level", "warning"], env=env, stdout=subprocess.DEVNULL)


async def wait_healthy(http: httpx.AsyncClient, timeout: float = 120.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            if (await http.get("/api/health")).status_code == 200:
                return
        except httpx.TransportError:
            pass
        await asyncio.sleep(0.1)
    raise RuntimeError("the server did not start")


async def total_steps(http: httpx.AsyncClient, run_ids: list[str]) -> int:
    runs = {r["id"]: r for r in (await http.get("/api/runs")).json()}
    return sum(int(runs[run_id]["step"]) for run_id in run_ids)


async def steps_per_second(http: httpx.AsyncClient, run_ids: list[str], seconds: float) -> float:
    began, before = time.monotonic(), await total_steps(http, run_ids)
    await asyncio.sleep(seconds)
    return (await total_steps(http, run_ids) - before) / (time.monotonic() - began)


async def stream(url: str, client: Client, stop: asyncio.Event) -> None:
    async with connect(url, max_size=2**24) as ws:
        while not stop.is_set():
            try:
                await asyncio.wait_for(ws.recv(), timeout=0.5)
            except TimeoutError:
                continue
            except Exception as exc:  # the server closed the stream
                client.closed.append(repr(exc))
                return
            client.messages += 1


@dataclass
class Poller:
    """One REST client reading a run's state `hz` times a second: answers, failures, latencies."""

    run_id: str
    answers: int = 0
    failures: list[str] = field(default_factory=list)
    latencies: list[float] = field(default_factory=list)


async def poll(http: httpx.AsyncClient, poller: Poller, hz: float, stop: asyncio.Event) -> None:
    next_at = time.monotonic()
    while not stop.is_set():
        began = time.monotonic()
        try:
            response = await http.get(f"/api/runs/{poller.run_id}/state")
            if response.status_code == 200:
                poller.answers += 1
            else:
                poller.failures.append(f"status {response.status_code}")
        except httpx.HTTPError as exc:
            poller.failures.append(repr(exc))
        poller.latencies.append(time.monotonic() - began)
        next_at += 1.0 / hz
        await asyncio.sleep(max(0.0, next_at - time.monotonic()))


def cpu_seconds(pid: int, learners_only: bool = False) -> float:
    """User + system CPU time so far of a process (Linux /proc, else 0); with `learners_only`, of the processes
    under it instead (the runs' workers, forked by its fork server) and not of the process itself."""
    tree = tree_cpu_seconds(pid)
    own = tree.get(pid, 0.0)
    return sum(tree.values()) - own if learners_only else own


def tree_cpu_seconds(pid: int) -> dict[int, float]:
    """User + system CPU seconds so far of a process and each of its descendants, by pid (Linux /proc)."""
    ticks = os.sysconf("SC_CLK_TCK")
    by_parent: dict[int, list[int]] = {}
    times: dict[int, float] = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as stat:
                fields = stat.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        by_parent.setdefault(int(fields[1]), []).append(int(entry))
        times[int(entry)] = (int(fields[11]) + int(fields[12])) / ticks
    found, todo = {}, [pid]
    while todo:
        current = todo.pop()
        found[current] = times.get(current, 0.0)
        todo.extend(by_parent.get(current, []))
    return found


@dataclass
class Loaded:
    """What one measurement under load gave."""

    rate: float
    message_rates: list[float]
    dropped: int
    pollers: list[Poller]


async def streamed_phase(http: httpx.AsyncClient, port: int, run_ids: list[str], args: argparse.Namespace) -> Loaded:
    """Steps per second while `args.clients` clients stream and `args.pollers` pollers poll."""
    stop = asyncio.Event()
    clients = [Client(run_ids[i % len(run_ids)]) for i in range(args.clients)]
    tasks = [asyncio.create_task(stream(f"ws://127.0.0.1:{port}/api/runs/{c.run_id}/stream", c, stop)) for c in clients]
    pollers = [Poller(run_ids[i % len(run_ids)]) for i in range(args.pollers)]
    async with httpx.AsyncClient(base_url=f"http://127.0.0.1:{port}", timeout=30.0) as polling:
        tasks += [asyncio.create_task(poll(polling, p, args.poll_hz, stop)) for p in pollers]
        await asyncio.sleep(1.0)  # all connected and streaming
        counted = [c.messages for c in clients]
        for p in pollers:
            p.answers, p.latencies = 0, []
        rate = await steps_per_second(http, run_ids, args.seconds)
        rates = [(c.messages - n) / args.seconds for c, n in zip(clients, counted, strict=True)]
        stop.set()
        await asyncio.gather(*tasks, return_exceptions=True)
    await asyncio.sleep(1.0)  # all gone
    return Loaded(rate, rates, sum(1 for c in clients if c.closed), pollers)


async def bench(args: argparse.Namespace) -> float:
    """Alternate measurements without and with clients (A B A B A) and compare their means."""
    port = free_port()
    alone: list[float] = []
    streamed: list[float] = []
    rates: list[float] = []
    dropped = 0
    pollers: list[Poller] = []
    cpu: dict[str, list[float]] = {"alone": [], "loaded": []}
    learner_cpu: dict[str, list[float]] = {"alone": [], "loaded": []}
    with tempfile.TemporaryDirectory(prefix="horde-bench-") as data:
        server = start_server(port, data)
        try:
            async with httpx.AsyncClient(base_url=f"http://127.0.0.1:{port}", timeout=60.0) as http:
                await wait_healthy(http)
                run_ids = []
                for seed in range(args.runs):
                    body = {"scenario": "experiment1", "seed": seed, "protocol": {"episodes": 0}}
                    response = await http.post("/api/runs", json=body, params={"start": "true"})
                    response.raise_for_status()
                    run_ids.append(response.json()["id"])
                await asyncio.sleep(args.warmup)
                for phase in range(2 * args.rounds + 1):
                    cpu_began, wall_began = cpu_seconds(server.pid), time.monotonic()
                    learner_began = cpu_seconds(server.pid, learners_only=True)
                    if phase % 2 == 0:
                        alone.append(await steps_per_second(http, run_ids, args.seconds))
                        print(f"  without clients: {alone[-1]:10,.0f} steps/s", flush=True)
                    else:
                        loaded = await streamed_phase(http, port, run_ids, args)
                        streamed.append(loaded.rate)
                        rates += loaded.message_rates
                        dropped += loaded.dropped
                        pollers += loaded.pollers
                        mean_rate = sum(loaded.message_rates) / max(1, len(loaded.message_rates))
                        answers = sum(p.answers for p in loaded.pollers) / args.seconds
                        print(
                            f"  with {args.clients} clients, {args.pollers} pollers: {loaded.rate:8,.0f} steps/s, "
                            f"{mean_rate:.1f} messages/s each, {answers:.0f} polls/s answered",
                            flush=True,
                        )
                    wall = time.monotonic() - wall_began
                    cpu["alone" if phase % 2 == 0 else "loaded"].append((cpu_seconds(server.pid) - cpu_began) / wall)
                    learner = (cpu_seconds(server.pid, learners_only=True) - learner_began) / wall
                    learner_cpu["alone" if phase % 2 == 0 else "loaded"].append(learner)
        finally:
            server.terminate()
            server.wait(timeout=30)

    without, with_clients = sum(alone) / len(alone), sum(streamed) / len(streamed)
    ratio = with_clients / without
    measured = f"means over {len(alone)} + {len(streamed)} measurements of {args.seconds:g} s"
    print(f"{args.runs} runs at full speed; {measured}")
    print(f"  without clients: {without:12,.0f} steps/s")
    print(f"  with {args.clients} clients, {args.pollers} pollers: {with_clients:,.0f} steps/s")
    print(f"  ratio:           {ratio:12.3f}   (goal >= 0.8)")
    mean_cpu = {k: sum(v) / len(v) for k, v in cpu.items()}
    print(f"  server CPU seconds per wall second: alone {mean_cpu['alone']:.2f}, loaded {mean_cpu['loaded']:.2f}")
    learner = {k: sum(v) / len(v) for k, v in learner_cpu.items()}
    if learner["alone"] > 0 and learner["loaded"] > 0:
        per_cpu = (with_clients / learner["loaded"]) / (without / learner["alone"])
        print(
            f"  the workers' CPU seconds per wall second: alone {learner['alone']:.2f}, loaded "
            f"{learner['loaded']:.2f}; steps per worker CPU second, loaded / alone: {per_cpu:.3f}"
        )
    if rates:
        print(
            f"  messages per client per second: min {min(rates):.1f}, mean {sum(rates) / len(rates):.1f}, "
            f"max {max(rates):.1f}; clients dropped: {dropped}"
        )
    failures = [f for p in pollers for f in p.failures]
    latencies = sorted(x for p in pollers for x in p.latencies)
    if latencies:
        p95 = latencies[int(0.95 * (len(latencies) - 1))]
        print(
            f"  polls: {sum(p.answers for p in pollers)} answered, {len(failures)} failed; latency median "
            f"{1000 * latencies[len(latencies) // 2]:.1f} ms, 95th percentile {1000 * p95:.1f} ms"
        )
    if failures or dropped:
        print(f"  FAILURES: {dropped} streams dropped, {len(failures)} polls failed: {failures[:5]}")
        return 0.0
    return ratio


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10.0, help="length of each measurement")
    parser.add_argument("--warmup", type=float, default=3.0)
    parser.add_argument("--clients", type=int, default=20, help="WebSocket clients streaming the runs")
    parser.add_argument("--pollers", type=int, default=20, help="REST clients polling the runs' state")
    parser.add_argument("--poll-hz", type=float, default=10.0, help="polls per second of each poller")
    parser.add_argument("--runs", type=int, default=1, help="runs learning at full speed")
    parser.add_argument("--rounds", type=int, default=2, help="measurements with clients (one more without)")
    args = parser.parse_args(argv)
    ratio = asyncio.run(bench(args))
    return 0 if ratio >= 0.8 else 1


if __name__ == "__main__":
    raise SystemExit(main())
