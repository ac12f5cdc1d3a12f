"""Learning throughput with and without WebSocket clients streaming.

Starts the server (`python -m horde.server`) on a free loopback port with a temporary data directory,
creates three runs of `experiment1` that learn at full speed (protocol.episodes = 0), and measures
the steps per second of all three together, alternately with no client and while 20 WebSocket
clients stream the runs (without, with, without, with, without: the machine's background load
drifts, so the means are compared). Learning must not wait for clients, so the ratio of the
two figures should stay near 1 (the goal is at least 0.8). It prints both figures, their ratio, and
the messages each client received per second. The server is stopped at the end.

Run: `python benchmarks/bench_stream.py [--seconds 10] [--clients 20] [--runs 3] [--rounds 2]`.
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


async def streamed_phase(
    http: httpx.AsyncClient, port: int, run_ids: list[str], args: argparse.Namespace
) -> tuple[float, list[float], int]:
    """Steps per second while `args.clients` clients stream; their message rates and how many were dropped."""
    stop = asyncio.Event()
    clients = [Client(run_ids[i % len(run_ids)]) for i in range(args.clients)]
    tasks = [asyncio.create_task(stream(f"ws://127.0.0.1:{port}/api/runs/{c.run_id}/stream", c, stop)) for c in clients]
    await asyncio.sleep(1.0)  # all connected and streaming
    counted = [c.messages for c in clients]
    rate = await steps_per_second(http, run_ids, args.seconds)
    rates = [(c.messages - n) / args.seconds for c, n in zip(clients, counted, strict=True)]
    stop.set()
    await asyncio.gather(*tasks, return_exceptions=True)
    await asyncio.sleep(1.0)  # all gone
    return rate, rates, sum(1 for c in clients if c.closed)


async def bench(args: argparse.Namespace) -> float:
    """Alternate measurements without and with clients (A B A B A) and compare their means."""
    port = free_port()
    alone: list[float] = []
    streamed: list[float] = []
    rates: list[float] = []
    dropped = 0
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
                    if phase % 2 == 0:
                        alone.append(await steps_per_second(http, run_ids, args.seconds))
                        print(f"  without clients: {alone[-1]:10,.0f} steps/s", flush=True)
                    else:
                        rate, client_rates, lost = await streamed_phase(http, port, run_ids, args)
                        streamed.append(rate)
                        rates += client_rates
                        dropped += lost
                        mean_rate = sum(client_rates) / len(client_rates)
                        print(f"  with {args.clients} clients: {rate:8,.0f} steps/s, {mean_rate:.1f} messages/s each")
        finally:
            server.terminate()
            server.wait(timeout=30)

    without, with_clients = sum(alone) / len(alone), sum(streamed) / len(streamed)
    ratio = with_clients / without
    measured = f"means over {len(alone)} + {len(streamed)} measurements of {args.seconds:g} s"
    print(f"{args.runs} runs at full speed; {measured}")
    print(f"  without clients: {without:12,.0f} steps/s")
    print(f"  with {args.clients} clients: {with_clients:10,.0f} steps/s")
    print(f"  ratio:           {ratio:12.3f}   (goal >= 0.8)")
    print(
        f"  messages per client per second: min {min(rates):.1f}, mean {sum(rates) / len(rates):.1f}, "
        f"max {max(rates):.1f}; clients dropped: {dropped}"
    )
    return ratio


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10.0, help="length of each measurement")
    parser.add_argument("--warmup", type=float, default=3.0)
    parser.add_argument("--clients", type=int, default=20)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--rounds", type=int, default=2, help="measurements with clients (one more without)")
    args = parser.parse_args(argv)
    ratio = asyncio.run(bench(args))
    return 0 if ratio >= 0.8 else 1


if __name__ == "__main__":
    raise SystemExit(main())
