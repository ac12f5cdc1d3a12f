"""A run of 1,000 mixed demons posted over REST and started: how many steps a second it learns.

The workload of the engine issue's second must-hold: TD(lambda), GTD(lambda) and GQ(lambda) demons, three target
policies, five discounts, over 8 tilings of 9 x 9 tiles of the world's (x, y), written as demon families (the
way a user writes a Horde this size). The server runs as users run it (`python -m horde.server` in its own
process, with its viser view); this script posts the spec to `POST /api/runs?start=true` at full speed, lets
it warm up (compilation, first steps), then reads the run's step count and the CPU time of the server and its
workers (`/proc`) over `--seconds`, `--repeat` times. It prints steps per wall second, steps per CPU second
and the load average beside them (the machine is shared: read the CPU figure when the load is high).

Run: `python -m benchmarks.bench_rest [--seconds 10] [--repeat 3] [--json PATH]`.
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from dataclasses import asdict, dataclass
from typing import Any

import httpx

from benchmarks.bench_health import start_server, wait_healthy
from benchmarks.bench_stream import free_port, tree_cpu_seconds

SENSORS = ["x", "y", "bump", *(f"in:z{i}{j}" for i in range(6) for j in (0, 3, 5))][:20]
GAMMAS = [0.0, 0.5, 0.8, 0.9, 0.95]
TARGETS = {  # three target policies of the TD and GTD demons
    "random": "uniform",
    "up": {"kind": "fixed", "probabilities": [0.7, 0.1, 0.1, 0.1]},
    "right": {"kind": "fixed", "probabilities": [0.1, 0.1, 0.1, 0.7]},
}
GQ_TEMPERATURES = [0.5, 1.0, 2.0, 4.0]


def zones() -> list[dict[str, Any]]:
    """Eight by six zones over a 1,000 x 1,000 world (the nexting world's layout; the sensors read some)."""
    width, height = 125, 1000 / 6
    return [
        {
            "name": f"z{i}{j}",
            "kind": "zone",
            "rect": [i * width, round(j * height), (i + 1) * width, round((j + 1) * height)],
        }
        for i in range(8)
        for j in range(6)
    ]


def spec() -> dict[str, Any]:
    """1,000 demons: 300 TD and 300 GTD (20 sensors x 5 discounts x 3 target policies each) and 400 GQ control
    demons (20 sensors x 5 discounts x 4 softmax temperatures), over 8 tilings of 9 x 9 tiles."""
    families: list[dict[str, Any]] = []
    for learner in ("td", "gtd"):
        for target, policy in TARGETS.items():
            families.append(
                {
                    "name": f"{learner}_{target}_{{s}}_g{{gamma}}",
                    "over": {"s": SENSORS, "gamma": GAMMAS},
                    "demon": {
                        "learner": learner,
                        "policy": policy,
                        "cumulant": {"sensor": "{s}"},
                        "discount": "{gamma}",
                    },
                }
            )
    families.append(
        {
            "name": "gq_{s}_g{gamma}_t{t}",
            "over": {"s": SENSORS, "gamma": GAMMAS, "t": GQ_TEMPERATURES},
            "demon": {
                "learner": "gq",
                "policy": {"kind": "softmax", "temperature": "{t}"},
                "cumulant": {"sensor": "{s}"},
                "discount": "{gamma}",
            },
        }
    )
    return {
        "name": "rest-1000-mixed",
        "seed": 1,
        "world": {
            "width": 1000,
            "height": 1000,
            "step": 25,
            "slip": 0.1,
            "start": [0, 0, 1000, 1000],
            "transient_reward": 0,
            "max_steps": 1000,
            "regions": zones(),
        },
        "features": {"kind": "tiles", "tilings": 8, "tiles": 9},
        "learning": {"lambda": 0.9, "alpha": 0.1, "alpha_w": 0.001},
        "behaviour": {"kind": "uniform"},
        "families": families,
        "protocol": {"trials": 1, "episodes": 0, "evaluation": {"rollouts": 0}},
    }


@dataclass
class Window:
    seconds: float
    steps: int
    cpu_seconds: float
    load: float

    @property
    def steps_per_second(self) -> float:
        return self.steps / self.seconds

    @property
    def steps_per_cpu_second(self) -> float:
        return self.steps / self.cpu_seconds if self.cpu_seconds > 0 else float("nan")


def process_cpu_seconds(pid: int) -> float:
    """User plus system CPU time so far of the server and the processes under it (its runs' workers; Linux)."""
    return sum(tree_cpu_seconds(pid).values())


def measure(client: httpx.Client, run: str, pid: int, seconds: float) -> Window:
    step0, cpu0, t0 = client.get(f"/api/runs/{run}").json()["step"], process_cpu_seconds(pid), time.perf_counter()
    time.sleep(seconds)
    step1, cpu1, t1 = client.get(f"/api/runs/{run}").json()["step"], process_cpu_seconds(pid), time.perf_counter()
    return Window(t1 - t0, step1 - step0, cpu1 - cpu0, os.getloadavg()[0])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=10.0, help="length of one measured window")
    parser.add_argument("--repeat", type=int, default=3, help="measured windows")
    parser.add_argument("--warmup", type=float, default=10.0, help="seconds of running before the first window")
    parser.add_argument("--json", help="also write the windows to this file")
    args = parser.parse_args()
    port = free_port()
    with tempfile.TemporaryDirectory() as data:
        server = start_server(port, data)
        try:
            url = f"http://127.0.0.1:{port}"
            wait_healthy(url)
            with httpx.Client(base_url=url, timeout=120) as client:
                created = time.perf_counter()
                answer = client.post("/api/runs", params={"start": "true"}, json=spec())
                answer.raise_for_status()
                run = answer.json()["id"]
                print(
                    f"created and started in {time.perf_counter() - created:.2f} s: "
                    f"{len(client.get(f'/api/runs/{run}/demons').json())} demons"
                )
                time.sleep(args.warmup)
                windows = [measure(client, run, server.pid, args.seconds) for _ in range(args.repeat)]
        finally:
            server.terminate()
            server.wait(timeout=30)
    for w in windows:
        print(
            f"{w.steps_per_second:8.1f} steps/s wall  {w.steps_per_cpu_second:8.1f} steps per CPU s  "
            f"({w.steps} steps in {w.seconds:.1f} s, {w.cpu_seconds:.1f} CPU s, load {w.load:.2f})"
        )
    if args.json:
        with open(args.json, "w") as f:
            json.dump([asdict(w) for w in windows], f, indent=2)


if __name__ == "__main__":
    main()
